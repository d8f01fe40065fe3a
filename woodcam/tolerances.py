"""Numerical tolerances used across woodcam, each with its reason.

Kept in one place so a test or a module never invents its own magic number.
"""

#: Chord tolerance (mm) when tessellating B-rep parts. 0.05 mm is below what a 0.1 mm
#: texel or a CNC finishing pass resolves, and keeps a 70 mm bowl around 10-30k triangles.
TESSELLATION_TOL_MM = 0.05

#: Angular tolerance (degrees) for tessellation: curved walls keep at most this normal jump.
TESSELLATION_ANGLE_DEG = 5.0

#: Relative volume error we accept between a carved mesh and an analytic volume. It is set by
#: the tessellation: a circle of radius r tessellated with chord tolerance t loses about
#: (2/3) t / r of its area, 0.1 % for r = 30 mm and t = 0.05 mm, doubled for margin.
CARVE_VOLUME_RTOL = 2e-3

#: A part is "outside the block" by less than this volume (mm^3) only through round-off of
#: the boolean; smaller outside volumes are not reported as warnings.
OUTSIDE_VOLUME_EPS_MM3 = 1e-3

#: Points are considered on a block face within this distance (mm): float32 mesh vertices
#: of a 100 mm block carry ~1e-5 mm of round-off.
ON_FACE_TOL_MM = 1e-4

#: Pixels of padding ("dilation") added around every chart in a baked atlas, so bilinear
#: filtering and mip levels up to 2^3 never reach unpainted texels.
ATLAS_PADDING_PX = 8

#: Maximum points evaluated in one batch by fields and appearances; bounds peak memory at
#: roughly 100 floats per point -> ~0.2 GB per batch.
MAX_BATCH_POINTS = 1 << 18

#: Smallest allowed radius-scaling value in the radial family (eq. 9 of seed 000) after the
#: linear blend; guards division by zero when a blend is extrapolated.
MIN_RADIUS_SCALE = 0.05

#: Grid step (mm) of a baked growth field. Growth time is smooth (a cone only at the pith), so
#: a 1 mm grid with cubic splines keeps ring lines within ~0.02 mm of the field it samples for
#: rings >= 2 mm wide, while a 50 mm cube costs only ~150k evaluations of the fitted field.
BAKE_SPACING_MM = 1.0

#: Border (mm) added around the block when baking, so cubic splines are not evaluated at the
#: edge of their grid on the block faces.
BAKE_MARGIN_MM = 2.0

#: Spacing (mm) at which ring traces are resampled before fitting: 0.5 mm is finer than any
#: ring's curvature radius away from the pith and keeps a fully traced 50 mm cube near 3-6k points.
TRACE_SAMPLE_STEP_MM = 0.5

#: Grey level at or above which a ring-map pixel counts as a ring pixel (maps are in [0, 1],
#: bright on ring boundaries; 0.5 is the natural mid-point of a soft boundary map).
RING_MAP_THRESHOLD = 0.5

#: Largest number of ring points the RBF fits use. Their dense solve is O(n^3): 2500 points take
#: ~1 s on one core; at 0.5 mm trace sampling that still keeps a point every ~1-2 mm of ring.
RBF_MAX_POINTS = 2500

#: Pixel size (mm) at which cut planes are sampled for the ring-accuracy metric: 10x finer than
#: the 1 mm threshold, so contour discretisation (< 0.01 mm for smooth fields) does not count.
EVAL_PIXEL_MM = 0.1

#: Distance thresholds (mm) of the ring-accuracy metric, as in seed 000's Table 1.
EVAL_THRESHOLDS_MM = (1.0, 2.0)

#: Largest relative difference between a face image's row and column pixel sizes (mm/px) that
#: is accepted as square pixels; a larger one means the image does not match the block size
#: (a wrong size_mm or an uncropped photo). 5 % allows a pixel of rounding on a 20 px face.
FACE_PIXEL_ASPECT_RTOL = 0.05
