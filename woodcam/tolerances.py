"""Numerical tolerances used across woodcam, each with its reason.

Kept in one place so a test or a module never invents its own magic number.
"""

#: Chord tolerance (mm) when tessellating B-rep parts at an explicit 0.1 mm texel. 0.05 mm is
#: below what a 0.1 mm texel or a CNC finishing pass resolves, and keeps a 70 mm bowl around
#: 20-30k triangles. By default the tolerance follows the part and the texel instead
#: (:func:`woodcam.cad.parts.auto_tolerance_mm`).
TESSELLATION_TOL_MM = 0.05

#: Default chord tolerance as a fraction of the texel (1 / texels_per_mm). OpenCascade meets its
#: linear deflection at its own sample points only: between them the mesh lies up to 2.1 x
#: deeper (measured at edge midpoints of spheres, r 5-200 mm), so a quarter texel keeps the
#: chord error at about half a texel: no texel samples the wood off the part by more than half
#: its size. (The demo bowl: 0.025 mm, 52k triangles; half a texel gave 32k.)
TESSELLATION_TEXEL_FRACTION = 0.25

#: Default chord tolerance as a fraction of the part's bounding-box diagonal: a small part is
#: meshed finer than the texel asks (a 17 mm knob at 0.017 mm), so its silhouette stays within
#: ~1/500 of its size (with OpenCascade's overshoot: about a pixel of a 500-pixel view).
TESSELLATION_REL_TOL = 1e-3

#: Smallest default chord tolerance (mm): below the OCCT modelling tolerance (1e-7 m) scale
#: nothing changes but the triangle count.
TESSELLATION_MIN_TOL_MM = 0.002

#: Angular tolerance (degrees) for tessellation: curved walls keep at most this normal jump.
#: Not raised to 10 degrees although that halves the triangles of fillets and small holes (lid
#: 12.3k -> 3.8k, bowl 31.8k -> 22.5k): a small sphere (r 8-15 mm) then loses 0.5 % of its
#: volume, beyond CARVE_VOLUME_RTOL; 5 degrees loses 0.13 %.
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

#: A resize, a ``gcode --stock`` or a parquetry leaf is inside its block within this fraction of
#: the block's largest side: a stock written back as a spec (12 significant digits,
#: :func:`woodcam._specs.format_op`) reads back ~1e-12 relative off its block, and origin + size
#: adds round-off; 1e-6 of a side (0.1 um of a 100 mm block) is no wood past the block.
IN_BLOCK_RTOL = 1e-6

#: Pixels of padding ("dilation") added around every chart in a baked atlas, so bilinear
#: filtering and mip levels up to 2^3 never reach unpainted texels.
ATLAS_PADDING_PX = 8

#: Default largest side of a baked atlas, texels (``max_atlas_px``, ``--max-atlas``): what
#: every GPU takes. The one home of the default: the bake functions, the preview pipeline and
#: the CLI option read it.
DEFAULT_MAX_ATLAS_PX = 4096

#: Maximum points evaluated in one batch by fields and appearances; bounds peak memory at
#: roughly 100 floats per point -> ~0.2 GB per batch.
MAX_BATCH_POINTS = 1 << 18

#: Smallest allowed radius-scaling value in the radial family (eq. 9 of seed 000) after the
#: linear blend; guards division by zero when a blend is extrapolated.
MIN_RADIUS_SCALE = 0.05

#: Largest sagitta (mm) between a G2/G3 arc and the chords it is split into. 0.005 mm is a
#: twentieth of the default 0.1 mm simulation cell, so chords never show in the height field,
#: and a 10 mm radius arc still needs only ~70 chords per turn.
ARC_CHORD_TOL_MM = 0.005

#: Largest difference (mm) between an I/J/K arc's start and end radius that we accept (plus
#: 1e-4 of the radius). CAM posts round centres to 3-4 decimals (1 um .. 0.1 um); LinuxCNC
#: accepts 0.002 mm relative; we allow 0.01 mm, beyond that the program is wrong.
ARC_RADIUS_MISMATCH_MM = 0.01

#: Heights (mm) within this of the stock surface count as "touching", not cutting, when the
#: simulation reports rapids through stock and cuts outside it: the float32 sweep kernel has
#: ~1e-5 mm round-off at 100 mm, and a CAM clearance plane sits >= 0.5 mm above the stock.
SIM_CONTACT_TOL_MM = 1e-4

#: Cell size (mm) of the reach check's own replay of a program (flute length, shank and holder
#: against the stock, :mod:`woodcam.toolpath.reach`): a shank or holder meeting the stock is a
#: millimetre-scale question, and a coarse grid keeps a 20 mm holder's window at ~80 x 80 cells.
REACH_GRID_MM = 0.5

#: Stock standing less than this (mm) above a shank or holder is not reported: the coarse
#: replay samples cell centres, and a CAM post's clearance is >= 0.1 mm.
REACH_TOL_MM = 0.05

#: Grid step (mm) of a baked growth field. Growth time is smooth (a cone only at the pith), so
#: a 1 mm grid with cubic splines keeps ring lines within ~0.02 mm of the field it samples for
#: rings >= 2 mm wide, while a 50 mm cube costs only ~150k evaluations of the fitted field.
BAKE_SPACING_MM = 1.0

#: Border (mm) added around the block when baking, so cubic splines are not evaluated at the
#: edge of their grid on the block faces.
BAKE_MARGIN_MM = 2.0

#: Depth (mm) beyond which a baked thin-plate spline of face points (the RBF hypothesis, a
#: residual) is interpolated from a grid of :data:`BAKE_SMOOTH_SPACING_MM` instead of evaluated
#: at every node (:mod:`woodcam.inference.baked`): its centres are on the faces, so it is smooth
#: there. The evidence fit's residuals (six noisy faces, amplitudes 1.2-10 years) baked so
#: against every node evaluated: seeds 57131 blocks 11 and 15 at most 0.0027 and 0.0048 years
#: off, 7777 block 10 (a 10-year residual) 0.016, all deep inside; the bake 2.45 -> 2.02,
#: 2.70 -> 2.08 and 1.70 -> 1.35 s on two cores. At least 3 mm deep instead, up to 0.047 years
#: off (the spline bends sharply near its centres).
BAKE_SMOOTH_DEPTH_MM = 5.0

#: Grid step (mm) of the coarse grid a baked spline is interpolated from deeper than
#: :data:`BAKE_SMOOTH_DEPTH_MM` (3 mm: up to 0.035 years off at 5 mm deep).
BAKE_SMOOTH_SPACING_MM = 2.0

#: Spacing (mm) at which ring traces are resampled before fitting: 0.5 mm is finer than any
#: ring's curvature radius away from the pith and keeps a fully traced 50 mm cube near 3-6k points.
TRACE_SAMPLE_STEP_MM = 0.5

#: Grey level at or above which a ring-map pixel counts as a ring pixel (maps are in [0, 1],
#: bright on ring boundaries; 0.5 is the natural mid-point of a soft boundary map).
RING_MAP_THRESHOLD = 0.5

#: Ring-map skeleton pixels where the bright band is wider than this factor times the face's
#: median band width are blobs, not ring lines (the U-Net paints rings 3-8 px wide; where it is
#: unsure, e.g. H11's face A, it paints 20-40 px blocks over several rings). Per face, so a face
#: whose rings are all wide bands (CN03's face A, median 14 px) keeps them.
RING_MAP_MAX_WIDTH_FACTOR = 2.5

#: Ring-map skeleton pieces shorter than this (px) are spurs of the thinning, not rings.
RING_MAP_MIN_PIECE_PX = 6

#: Ring-map pixels within this distance (mm) of a face's knot mask (``extras["knot_mask"]``) are
#: not ring observations: the ring detector fires on the knot's own rings and the stem's rings
#: bend around the knot, neither of which the stem's growth field describes. On H11 the bent
#: rings reach about 3 mm (15 px) beyond the knot's dark disc (looked at on faces C and F).
KNOT_MASK_MARGIN_MM = 3.0

#: A Mokume knot mask with at most this many dark pixels marks the knot's centre rather than its
#: outline (H11's C and F masks are one pixel each); it is grown into the knot's dark region.
KNOT_POINT_MAX_PX = 16

#: Gaussian smoothing (px) of the photo's luminance before growing a knot region: wider than
#: the latewood lines inside the knot (2-3 px on 256 px faces), so the knot is one dark blob.
KNOT_REGION_SMOOTH_PX = 4.0

#: Leave-one-face-out scores (``woodcam.inference.holdout``) count ring-map ridge pixels within
#: 1 and 2 face pixels of a predicted ring line and the reverse (issue 5: "within 1 and 2 pixels"),
#: and within 5 px: about 1 mm on a 256 px Mokume face of a 50 mm cube, Table 1's mm scale.
HOLDOUT_THRESHOLDS_PX = (1.0, 2.0, 5.0)

#: Predicted ring lines are sampled every 0.25 px for the distance queries: the sampling error
#: (at most half a step) stays an eighth of the 1 px threshold.
HOLDOUT_LINE_STEP_PX = 0.25

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

#: Fewest pixels a face photo may have on its shorter side (``block from-photos``): fewer hold no
#: rings the detector can find, and detection then reads noise (a 20 x 20 px photo set gave a
#: false 'looks mirrored' on a face with no rings). Measured on Mokume CN03 and H11 resized to
#: N px a side (a 50 mm cube): at 20-32 px no ring is found on 3 of CN03's 6 faces, at 48 px
#: rings are found on all 12 faces; 48 px holds ten of the detector's shortest ring spacing
#: (4.5 px, :data:`woodcam.detect.rings.WAVELENGTH_RANGE_PX`), a phone photo thousands.
MIN_FACE_PHOTO_PX = 48

#: Fewest pixels a mm (along its coarser axis) a face image must have for the face-layout check
#: (:func:`woodcam.detect.layout.check_face_layout`) to judge it; a coarser face is listed as not
#: checked. Measured on correct layouts resized (a 50 mm cube), with rings found on every face:
#: Mokume CN03 scored a turned 'back' past the 0.15 margin at 0.64-1.28 px/mm (32-64 px a side;
#: its best wrong variant +0.27, +0.20, +0.15), +0.12 at 1.6 and +0.07 at 1.92; H11 stayed under
#: (+0.14 at 0.64); synthetic cubes of 1.5 mm rings (flat- and quarter-sawn) gave false alarms
#: up to 1.92 px/mm (+0.22, +0.29; 2.9 px a ring) and none from 2.56 (+0.04, +0.08). From
#: 2.56 px/mm the real faces' wrong layouts (each face turned 90, 180, mirrored) are still found:
#: CN03 15 of 18, H11 17 of 18. Not px per ring alone: CN03's rings are 5-13 mm apart (over 6 px a
#: ring at 1.28 px/mm) and it still misread, the check's filters being in mm (0.2 mm smoothing,
#: 1 mm shift). Synthetic cubes of 3 and 6 mm rings (flat-, quarter-sawn, rift; seeds 48611 and
#: 29837; 320 px photos brought down by LANCZOS as 'block from-photos' does; rings found on every
#: face) still gave false alarms at the 2.5 first set here: 3 of 12 cubes at 2.50 px/mm (+0.15,
#: +0.16, +0.15: the quarter-sawn 'right' mirrored), 4 at 2.56 (to +0.17), 2 at 2.62, none from
#: 2.68 (+0.14 at 2.68 and 2.74, +0.12 at 2.76 and 2.80, +0.11 at 2.90, +0.09 at 3.00; 72
#: cubes). CN03 and H11 as laid out stay unflagged at 2.56-3.00; of their 18 wrong layouts each
#: (the face named, counted on photos detected first) 14 and 17 are found at 2.56, 12 and 16 at
#: 2.76 and at 3.00: a face between 2.5 and 2.75 px/mm is now not checked instead.
LAYOUT_MIN_PX_PER_MM = 2.75

#: Largest error (years) allowed between a refined synthetic ring trace vertex and its integer
#: iso-line. Newton refinement on the true field reaches ~1e-9 years in three steps; vertices that
#: do not (on a field kink or where the gradient vanishes, e.g. at the pith) are dropped.
#: The acceptance test uses 1e-3 years (about 3 um at 3 mm rings), so 1e-4 leaves margin.
TRACE_ISO_TOL_YEARS = 1e-4

#: Finite-difference step (pixels) for the in-face gradient used to refine ring traces: small
#: enough to resolve 1.5 mm rings at 5 px/mm, large enough that float64 round-off of years of
#: order 100 stays ~1e-12 relative.
TRACE_FD_STEP_PX = 1e-3

#: Ring maps stored as 16-bit PNG come back within half a quantisation step, 0.5 / 65535.
RING_MAP_QUANT_16BIT = 0.5 / 65535

#: Ring maps stored as 8-bit PNG (and Mokume's own maps) carry 0.5 / 255 of quantisation.
RING_MAP_QUANT_8BIT = 0.5 / 255

#: Colours a wood returns may overshoot [0, 1] by this much (round-off of blends and colour
#: transforms) and are clipped; a larger excursion is an error (e.g. 0..255 colours passed).
COLOR_RANGE_TOL = 1e-3

#: A surface normal given to ``Wood.color`` must be at least this long (any unit: it only
#: weighs the block axes, eq. 10): shorter is no direction (a NaN or a zero normal was coloured
#: as an equal blend of the three axes' colourings without a word).
MIN_NORMAL_LENGTH = 1e-6

#: A point counts as on a knot's surface (the envelope of its elliptic cross-sections) when its
#: signed distance is above -this (mm): the projection onto the knot's centre curve converges
#: to ~1e-5 mm, and cross-section points truly inside a sharply bent knot are >= 0.01 mm in.
KNOT_SURFACE_TOL_MM = 1e-3

#: Extra reach (texels) of the bake's conservative rasterisation beyond the exact bilinear
#: footprint of 1 texel: covers float32 UVs in GLB files (2^-24 x 8192 texels = 5e-4) and the
#: float32 edge tests (~1e-3 texel), so a sample exactly on a chart border never reads an
#: unpainted texel.
RASTER_MARGIN_TEXELS = 0.02

#: Triangles whose texel-space area (texels^2) is below this are degenerate in UV: their
#: barycentric inverse is ill-conditioned, so the baker skips them (neighbours paint the texels).
MIN_UV_AREA_TEXELS2 = 1e-10

#: Mean colour error (fraction of full scale) allowed when a translation network trained on one
#: face redraws another face of the same axis from its ARF, against that face's photo resampled
#: to the grid (synthetic photos that are a known colour function of the ARF). The network is
#: small and trained for seconds ("draft"); the remaining error sits on the sharp latewood ->
#: earlywood steps. Measured 0.02-0.03 on the test cube; 0.04 leaves margin across seeds.
NEURAL_FACE_MAE = 0.04

#: Mean colour error allowed inside the block (trilinear lookup in the colour volumes against the
#: known colour function): the face error plus the trilinear blur of ring steps between cell
#: centres (cells of 0.67 mm against 3.5 mm rings in the test). Measured ~0.03.
NEURAL_VOLUME_MAE = 0.05

#: Growth history of the radial fit (``woodcam.inference.radial._fit_growth_history``): each
#: year's level is shrunk towards the mean ring width as if this many points (about 10 mm of ring
#: at the 0.5 mm trace spacing) sat exactly on it, so a ring glimpsed on a few points cannot bend
#: the warp; 3 alternations of levels and shape change the levels by < 0.01 year after that
#: (CN03, eq. 7-9 blocks); the 1e-3 year step keeps the levels strictly increasing for
#: interpolation without moving any ring visibly (1e-3 year is a few micrometres).
RING_HISTORY_PRIOR_POINTS = 20.0
RING_HISTORY_ROUNDS = 3
RING_HISTORY_MIN_STEP = 1e-3

#: Nodes either side of a mesh where woodify rasterises exact distances (and closest points).
#: 2 covers the first layer of nodes outside the input in every direction (distance <= sqrt(3)
#: nodes) with a node to spare, which both fast marchers start from.
WOODIFY_BAND_NODES = 2

#: Distance (voxels) within which a grid node lies ON the input surface for the isotropic fast
#: march, which then starts it as just inside (at minus this distance). Floating point puts the
#: nodes of a face on a node plane 0 or ~1e-15 voxel from it, on either side; 1e-6 voxel is far
#: above that noise and moves the surface by nothing a section or a mesh can show.
WOODIFY_ON_SURFACE_VOXELS = 1e-6

#: Clearance (voxels) the grown solid keeps from obstacles. The signed distance of a convex
#: obstacle is convex, so its linear interpolation between two nodes crosses zero slightly
#: INSIDE the obstacle (by the sagitta, h^2 / 8a for a rod of radius a: 0.04 h at a = 3 h);
#: 0.1 voxel keeps every marching-cubes vertex outside rods thicker than ~1.5 voxels.
WOODIFY_OBSTACLE_CLEARANCE_VOXELS = 0.1

#: Exported shading normals are averaged over the faces round a vertex whose normals lie within
#: this angle of each other; a sharper edge keeps two normals (a crease). 30 degrees is the
#: common CAD/DCC default (Blender's auto-smooth, three.js' toCreasedNormals examples): a
#: tessellated cylinder (5 degree facets) shades smooth, a box edge (90 degrees) stays sharp.
CREASE_ANGLE_DEG = 30.0

#: Two exported corners are the same position when they agree to this (mm); the baked mesh is
#: split at UV seams, so positions, not vertex indices, decide which faces meet at a vertex.
CREASE_WELD_MM = 1e-6

#: Default triangle budget of a tessellated B-rep part: above it, load_part re-meshes with
#: looser tolerances and says so. Public STEP parts reached 226k-312k triangles at the fixed
#: 0.05 mm / 5 deg defaults and took 4-10 min to bake; 120k keeps the demo bowl (~32k) and the
#: other examples untouched while bounding the unwrap (xatlas is super-linear in chart size).
MAX_PART_TRIANGLES = 120_000

#: The most a mesh part's surfaces may move (a fraction of its bounding-box diagonal) when it is
#: simplified to the triangle budget; past it the part is refused, --max-triangles named. 1 %
#: is ten times the B-rep default chord (TESSELLATION_REL_TOL): visible on the part, and said
#: with the tolerance used, but the shape kept (an icosphere of 5120 triangles simplified to
#: 1000 moves 0.4 % of its diagonal and loses 2-3 % of its volume); beyond it a small body
#: (forty 1 mm boxes in a row) is ground down until it vanishes.
MESH_SIMPLIFY_MAX_REL_TOL = 0.01


#: Parquetry cut files: a join between two segments counts as a corner when the tangent turns by more than this
#: (sine of the angle): seams are C1 in theory, and 1e-5 mm rounding of handles about 0.5 mm
#: long turns them by < 1e-4.
PARQUETRY_CORNER_SIN = 0.01

#: Parquetry cut files: what a disc of diameter min_piece_mm cannot reach, away from corners, is tolerated when it
#: is thinner than twice this (mm) everywhere: seams bend no tighter than
#: min_piece_mm / 2, so only the flattening of curves (chords within ~3 um) and the disc's
#: polygon (32 segments a quarter: 2.5 mm * (1 - cos(pi / 128)) = 0.8 um) remain; a sliver or
#: neck thinner than min_piece_mm sticks out by its own length, far more than this.
PARQUETRY_WIDTH_TOL_MM = 0.05

#: Parquetry cut files: a concave bend counts as tighter than the tool when its radius is below this fraction of
#: the tool radius (the seams are smoothed to the full radius; this allows for the sampling
#: of the curvature check).
PARQUETRY_CURVATURE_SLACK = 0.98

#: Sliced veneers (``slice_veneers``): a pixel is supersampled only where the centre samples
#: of its 3 x 3 neighbourhood differ by more than this in some RGB channel; elsewhere the wood
#: is smooth at the pixel's scale and its centre sample stands for the pixel's mean. At 0.01
#: (with the across-the-grain sampling of ``_supersampled``) leaves of walnut, oak, maple and
#: cherry at 4 px/mm differ from full 3 x 3 sampling by 2.5e-4 to 3.1e-4 on average, with
#: 0.4-1 % more Sobel energy, at a third of its CPU time; 0.02 would leave a further 14-28 %
#: of the pixels unsampled for two to three times the difference.
PARQUETRY_SUPERSAMPLE_TOL = 0.01

#: Histogram matching (eq. 2, ``woodcam.parquetry.features.match_histogram``): target grey
#: levels that differ by at most this are one level and share one quantile. Resampling a target
#: to the panel in float32 (``cv2.resize``) and its grey mix leave a flat area a few float32
#: ulps apart (a flat 200/255 background: 0.78431356 to 0.7843139, 3e-7), and ranking those as
#: distinct levels spread the flat area over a fifth of the wood's histogram in a fine grid
#: pattern (std 0.058). Half the finest step an image file stores (1/65535, 16-bit): distinct
#: levels of any 8- or 16-bit target stay distinct, and only a ramp rising less than this per
#: pixel is read as flat (a 16-bit ramp of 0.004 over 1000 pixels, below one 8-bit step).
PARQUETRY_GREY_LEVEL_TOL = 2.0 ** -17

#: Evidence-based choice of a fit (``woodcam.inference.evidence``, issue 12 part 1).
#: A face takes part in leave-one-face-out only with at least this many ring points: fewer
#: (a face crossed by one short ring) scores by chance.
EVIDENCE_MIN_FACE_POINTS = 20

#: Held-out points scored per face (a fixed random subset): 400 points give a share to about
#: +-2.5 % (binomial std at 50 %), finer than the differences between hypotheses that matter.
EVIDENCE_MAX_HELD_POINTS = 400

#: Ring points of the RBF hypotheses (full and held-in fits): the dense solve is O(n^3), and
#: 1000 points (one every ~2-4 mm of ring on a traced 50 mm cube) keep each refit near 0.1 s.
EVIDENCE_RBF_POINTS = 1000

#: Smoothing of the residual RBF per point (scipy's ``smoothing`` is summed over points): the
#: residual is meant to carry distortions a few mm wide, not each trace's jitter.
EVIDENCE_RESIDUAL_SMOOTHING = 1e-3

#: Small-scale distortion (issue 12 part 4, :mod:`woodcam.fields.residual`,
#: :func:`woodcam.inference.residual.fit_face_residual`): knot spacing (mm) of each face's
#: residual B-spline. A cubic B-spline follows a wave down to about three knot intervals, so
#: 3 mm keeps waves of 10 mm (the shortest of the issue's wavy figure, seed 000 Fig. 16b) and
#: leaves out a trace's jitter between neighbouring rings (2-5 mm apart).
RESIDUAL_SPACING_MM = 3.0

#: Depth (mm) of the residual's Gaussian fall-off from a face: a quarter of a 20 mm wave, so what
#: one face shows of a wave is carried onto its neighbour's edge zone (where leave-one-face-out
#: can check it) but not guessed deep inside, where no face pins it (0.02 of it at 2 depths).
RESIDUAL_DEPTH_MM = 5.0

#: Penalties of the residual's B-spline coefficients, relative to the data (each face's ring
#: points weigh as much in all as one point per knot cell): ridge (pulls unobserved parts to 0:
#: with the slope term, what an observed face shows of the residual dies out over
#: sqrt(slope / ridge) = 2.2 knot intervals onto a face it does not see), slope (first
#: differences) and curvature (second differences, P-spline style). A 10 / 20 mm wave keeps
#: about 0.6 / 0.85 of its amplitude on an observed face: the residual is strongly damped, and
#: leave-one-face-out decides whether it stays.
RESIDUAL_RIDGE = 0.02
RESIDUAL_SLOPE = 0.1
RESIDUAL_CURVATURE = 0.02

#: Huber threshold (years) of the residual's robust fit (two reweighting rounds): a trace
#: labelled one year off (the noisy benchmark's 3 %) or a ring piece numbered one year off is a
#: whole-ring residual, and a wave of the issue's 0.5-1 ring is carried by many points, not one
#: trace.
RESIDUAL_HUBER_YEARS = 0.25

#: Ring points the residual is fitted to (a fixed random subset): 4000 keep a face's wave
#: sampled every ~1 mm of ring on a 50 mm cube and the sparse solve near 0.1 s.
RESIDUAL_MAX_POINTS = 4000

#: The residual is kept only when, with it fitted on the other faces in each fold, the held-out
#: faces' mean score (:func:`woodcam.inference.evidence.face_score`, percent) rises by at least
#: this (about one binomial std of a 400-point share at 90 %: a gain the held-out points show,
#: not their sampling) ...
RESIDUAL_MIN_GAIN = 1.0

#: ... and no held-out face's score falls by more than this (two binomial std at 50 % of 400
#: points): a residual that helps some faces by misleading another is not kept.
RESIDUAL_MAX_FACE_LOSS = 5.0

#: A chosen fit is flagged "contradicted" when some held-out face has fewer of its ring points
#: within 2 mm of the predicted ring line than this (percent): the issue's bar for a block.
EVIDENCE_MIN_FACE_SHARE_2MM = 80.0

#: Unlabelled rings are numbered by the lowest-cost pith basin whose neighbour-step consistency
#: (share of neighbouring rings one year apart, :func:`woodcam.inference.radial.step_consistency`)
#: is within this of the best basin's. Good numberings of H11's ring maps score 0.60-0.73
#: (unlinked pieces of one ring make steps of 0, more or fewer with the basin), the wrong ones
#: seen 0.05-0.42 (H11's tilted and merged folds), a clean synthetic block's > 0.9. Set before
#: the runs on detected rings, and not retuned on them.
NUMBERING_STEP_MARGIN = 0.1

#: A numbering with fewer than this share of neighbouring rings one year apart is wrong more
#: often than right: the pith search is repeated on other point subsets
#: (:func:`woodcam.inference.radial._numbered_basins`), at most :data:`NUMBERING_RESEARCHES`
#: times. Between the good numberings of H11 (0.60-0.73) and the wrong ones (0.05-0.42) above.
NUMBERING_MIN_STEP = 0.5
NUMBERING_RESEARCHES = 2

#: Hypotheses whose mean held-out score is within this many percent points of the best are
#: "accepted": their spread is the fit's per-point uncertainty.
EVIDENCE_ACCEPT_MARGIN = 5.0

#: Depth (mm) from the nearest observed face over which the evidence fit passes from the chosen
#: hypothesis (on the faces) to the mean of the accepted ones (deeper): the held-out evidence
#: scores ring points within 1 and 2 mm, so within 2 mm of a face the faces pin the chosen fit,
#: and deeper the hypotheses the evidence cannot tell apart are averaged
#: (:func:`woodcam.inference.evidence.blend_away_from_faces`, opt-in). Real cubes,
#: leave-one-face-out, blended in every fold (no evidence gate): 1 / 2 / 5 mm gave H11
#: 2.16 / 2.17 / 1.94x chance within 2 px, CN03 12.9 / 13.1 / 13.4x; 2 / 5 / 10 mm with the gate:
#: H11 2.16 / 1.94 / 1.78x, CN03 19.2 / 18.1 / 17.0x (offline, from cached fold fits).
EVIDENCE_BLEND_DEPTH_MM = 2.0

#: A refinement hypothesis (the knots' ring bend on the stem) competes only while its base's
#: mean held-out score is within this many percent points of the best plain hypothesis'
#: (:func:`woodcam.inference.evidence.choose`). H11's fold without its bottom face: stem 19.8
#: points below the best, its bend won and predicted the face below chance. Dev seed 9101, six
#: noisy faces, knotted blocks: the stems under bends that help are 0-7.2 points below the best;
#: dev seed 63311 block 1, six faces: 12.4 below, its cone bend 13.1 above the best plain
#: hypothesis and 94.5 / 98.1 % within 1 / 2 mm on the cut planes (the plain one chosen at 10
#: points: 36.9 / 54.6). 15 since :data:`EVIDENCE_REFINE_GAIN_MARGIN` guards the choice too.
EVIDENCE_REFINE_BASE_MARGIN = 15.0

#: A refinement is chosen only when its mean held-out score beats every plain hypothesis' by
#: more than this many percent points (:func:`woodcam.inference.evidence.choose`): hypotheses
#: closer than :data:`EVIDENCE_ACCEPT_MARGIN` are ones the evidence cannot tell apart, and then
#: the field without the extra term is kept. H11's fold without its right face, knot cones on:
#: the bend 52.1 against the best plain hypothesis 48.9 (+3.2), and it predicted the right face
#: at 0.3 % within 2 px (the plain one 24.9 %); bends that help on dev seed 63311 win by 6-27.
EVIDENCE_REFINE_GAIN_MARGIN = EVIDENCE_ACCEPT_MARGIN

#: Where its base is the best plain hypothesis, a refinement takes the base's place
#: (:func:`woodcam.inference.evidence.choose`) unless it misses more than this many times what
#: the base misses of the held-out score (``100 - mean``): a bend round knots whose rings the
#: faces do not show bent is rejected (the planted masks of ``test_knot_bend``: the stem ~100 %,
#: its bend 93.0 %). Dev seeds 7777, 63311, 9101 and 21, knotted blocks whose stem was the best
#: plain hypothesis and whose bend was the better inside (six noisy faces): the bends missed
#: 0.7-1.9 times what their stems missed (7777/8: 19.0 against 10.1 points).
EVIDENCE_REFINE_MISS_RATIO = 2.0

#: Uncertainty added per mm from the nearest observed face (years/mm): a prior, not a
#: measurement; 0.02 makes the middle of a 50 mm block seen from one face half a ring unsure.
EVIDENCE_UNSEEN_YEARS_PER_MM = 0.02

#: Uncertainty (years) added inside a fitted knot, fading to 0 one knot radius beyond it
#: (:meth:`woodcam.fields.knot_strands.StemWithKnots.knot_halo`): the knot's own rings and
#: the stem's bend round it come from a model fitted to the masks, not from traced rings.
#: Measured on dev seed 9101 (4 blocks, noisy, six faces): without it the confident and unsure
#: ring lines were equally right (95.3 vs 95.8 % within 2 mm), the misses sitting round the
#: knots; with it 98.4 vs 92.6 % (72 % of the line points confident, was 92 %).
EVIDENCE_KNOT_UNCERTAINTY_YEARS = 1.0

#: Grid spacing (mm) on which the hypotheses' spread is sampled before interpolation to the
#: bake grid: the spread is smooth over several mm, and the RBF hypotheses are slow to evaluate.
EVIDENCE_SPREAD_SPACING_MM = 4.0

#: Knot-mask regions smaller than this (pixels) are not knot exits (speckle of a detector).
KNOT_MIN_AREA_PX = 12

#: ... and smaller than this share of the largest region on the same face (H11's grown mask of
#: face C has a 150 px bud beside its 21 000 px knot).
KNOT_MIN_AREA_SHARE = 0.1

#: Two knot exits on different faces are one branch when the line joining them makes more than
#: this angle with the stem axis: branches leave the stem at 50-90 degrees (seed 001's logs).
KNOT_PAIR_MIN_ANGLE_DEG = 40.0

#: A knot seen at one exit runs into the block down the stem's year gradient (toward the pith)
#: only where that direction enters through the exit's face at less than ~78 degrees from its
#: normal (cos 0.2); more grazing, the fitted stem's gradient there is not the knot's direction
#: (a knot exits a face it crosses, so it cannot run along it) and the face normal is used.
KNOT_MIN_ENTRY_COS = 0.2

#: A knot seen at one exit is a ray from the fitted pith through the exit
#: (:func:`woodcam.inference.knots._pith_ray`) only where the exit lies at least this far from
#: the pith (mm): the pith fitted from three faces is a few mm off (dev seed 7777 block 6: 7.6
#: mm from the exit with three faces, 11.4 with six), and 3 mm at 10 mm turns the ray 17 degrees.
KNOT_RAY_MIN_PITH_MM = 10.0

#: Rises (degrees from the cross-section toward the pith's tangent) tried for a knot seen at one
#: exit (:func:`woodcam.inference.knots._ray_rises`): seed 001's spruce knots start at about -1
#: and end at -11 degrees (its fits to Gran_1), broadleaf and pine branches rise 10-40; a block
#: may lie either way up, so both signs.
KNOT_RAY_RISES_DEG = (-40.0, -20.0, 0.0, 20.0, 40.0)

#: Ring points the stem's quick refit of each rise tried uses (no growth history): on dev seeds
#: 7777 and 63311 (three noisy faces) the bend alone scored the same, 67.8 / 67.7 % within 2 mm,
#: as with the full refit of 1000 points and every 10 degrees, at 0.6 of the CPU.
KNOT_RAY_REFIT_POINTS = 400

#: Cap (mm) of a ring point's distance from its ring when the rises are compared: a mislabelled
#: point (3 % of the noisy traces) is a ring or more off and would otherwise weigh most.
KNOT_RAY_MISFIT_CAP_MM = 3.0

#: Two exits are one branch only when the stem's years along the line between them do not dip
#: more than this (years) below both exits': a dip is the pith, and a branch grows out from the
#: pith on one side only (half a ring: more than a trace's mislabel or a fit's wobble).
KNOT_PITH_YEARS = 0.5

#: A branch grows out of the pith, so the line through two exits of one knot passes the fitted
#: stem's pith beyond one of them: within this share of the pith distance of the exit nearer it
#: (the sine of the angle, seen from that exit, between the line and the way to the pith: 0.4,
#: 24 degrees), the pair is taken first, the line nearest the pith first; the others after them,
#: in distance order (:func:`woodcam.inference.knots.strands_from_exits`). On dev seeds 7777 and
#: 63311 (six noisy faces) the true pairs' share was 0.06-0.22 (16 pairs; beside them 0.40 and
#: 0.86 for two knots sharing an exit, and two blocks whose exit lies on the pith or whose
#: fitted pith is far off); the false pairs' 0.5 and more but for five of 24 at 0.11-0.33. In
#: distance order alone dev seed 21 block 22 paired a knot's exit with a knot cutting a block
#: corner (its bend within 2 mm 66.6 %; in this order 99.8 %); by the line's miss alone, without
#: this share, seed 50287 block 6 (its ends 9 and 14 mm from the pith, every line there passes
#: within that of it) paired two wrong ends first (78.8 -> 59.9 %).
KNOT_PAIR_MAX_MISS_SHARE = 0.4

#: The fitted pith is a few mm off on a knotted block: a line's miss is counted as at least this
#: (mm), so lines within it of the pith are alike and the nearest exits pair first, and where
#: one exit lies on the pith (every line through it passes there) none passes
#: :data:`KNOT_PAIR_MAX_MISS_SHARE` (dev seed 7777 block 7).
KNOT_PAIR_MISS_FLOOR_MM = 3.0

#: A whorl's branches leave the pith together, so near it one exit can be two knots'. An exit
#: left unpaired pairs with an exit already taken, nearer the pith, when their line passes the
#: pith within this many mm and within :data:`KNOT_SHARE_MAX_MISS_SHARE` of the taken exit's
#: pith distance. The true shared pairs of dev seed 7777 and seed 50287 missed the fitted pith by
#: 3.9 and 8.1 mm.
KNOT_SHARE_MAX_MISS_MM = 10.0

#: :data:`KNOT_PAIR_MAX_MISS_SHARE` for a shared exit (0.5, 30 degrees): its mask is two knots'
#: and its middle lies between them, so each knot's line through it passes the pith less closely
#: (shares 0.30 and 0.40 on seeds 50287 and 7777).
KNOT_SHARE_MAX_MISS_SHARE = 0.5

#: Another pairing of knot ends than the order of :data:`KNOT_PAIR_MAX_MISS_SHARE` is taken only
#: where its cones cut the masks better, the least IoU of its pairs' cones higher than the
#: order's by this (:func:`woodcam.inference.knots._pairings`): the IoU of one cone fitted to two
#: ends is a pixel's worth of noise apart between pairings that are as good (57131/19: 0.730
#: against 0.724, and the rings' choice of the two lost 1.3 points); the exchanged crossed pairs
#: of 9101/5 gained 0.096 (0.898 against 0.802).
KNOT_PAIRING_MIN_IOU_GAIN = 0.02

#: ... and where its bend, fitted in full, leaves less misfit on the rings than the order's by this
#: share (:func:`woodcam.inference.knots.fit_knotted_stem`; the misfit moves a few per cent
#: between pairings the rings cannot tell apart: 63311/9's other pairing was 0.2 % better on the
#: rings and 29 points worse inside; 9101/5's exchanged pairs were 31 % better).
KNOT_PAIRING_MIN_MISFIT_GAIN = 0.05

#: Spacing (mm) at which the knot masks are sampled for a knot's cone fit
#: (:func:`woodcam.inference.knots._fit_cone`): knots are 2-20 mm across, so a 3 mm exit still
#: has ~30 samples, and a 80 mm face ~6400.
KNOT_CONE_SAMPLE_MM = 1.0

#: Width (mm) of the logistic edge of the cone fit's inside-ness: about two mask samples, so
#: a sample's vote is smooth across the mask's pixel edge and its jagged outline.
KNOT_CONE_EDGE_MM = 1.0

#: Knot-free samples this far (mm) beyond twice the starting radius of the starting cone are
#: left out of its fit: they cannot pull it, and leaving them out keeps the fit fast.
KNOT_CONE_REACH_MM = 8.0

#: Function evaluations of one start of a knot's cone fit (8 parameters): the fits on dev
#: seed 7777 settle within ~30.
KNOT_CONE_MAX_NFEV = 40

#: A cone fit's start within this angle (degrees) of a start already fitted to the same masks
#: takes that fit (:func:`woodcam.inference.knots._fit_cone`): the start down the stem's years
#: moves by a few degrees between folds and rounds, and on seed 91841 block 7 (six faces) its
#: 29 starts, within 5.6 degrees of each other, ended in one cone where the fit converged (0.0
#: degrees apart) and lost to a start along the exits' principal axes where it did not.
KNOT_CONE_START_REUSE_DEG = 8.0

#: Smallest knot radius (mm) a fitted cone gives anywhere along its strand (a branch at the
#: pith is a few mm thick; seed 001's logs start at 2-6 mm).
KNOT_CONE_MIN_RADIUS_MM = 1.0

#: A knot seen at one end (its exits over two or three faces at a block edge or corner) is a
#: strand only where its masks span at least this many cone radii along the fitted cone: a
#: shorter end does not pin the cone's direction (a round cut fits any axis through it). Since
#: FIT_VERSION 10; 1.0 tried with FIT_VERSION 25 (dev and fresh knotted blocks, six and three
#: faces): dev six faces 89.27 -> 88.67 % within 2 mm (7777/10, an end of 17.0 mm against 17.55,
#: 66.3 -> 51.0), the rest within 0.5 either way; README "A knot seen at one corner".
KNOT_END_MIN_SPAN_RADII = 1.5

#: Exits on two faces whose mask samples come this close (mm) across the edge between the faces
#: are one knot end (a knot cut by a block edge): two sample spacings, so a mask that reaches
#: the edge on both sides always touches.
KNOT_END_TOUCH_MM = 2.0 * KNOT_CONE_SAMPLE_MM

#: Rounds of the joint stem + knot-bend fit (:func:`woodcam.inference.knots.fit_knotted_stem`):
#: each refits the stem to the years less the bend its knots put there. Dev seed 21, six noisy
#: faces, blocks 1 / 9 / 10 within 1 mm: 1 round 97 / 53 / 97 %, 2 rounds 99 / 68 / 98 %, 4
#: rounds 99 / 74 / 98 %; a warm-started round costs about a quarter of a stem fit.
KNOT_BEND_ROUNDS = 3

#: Faces carrying rings that the knots' bend with a residual (the ``"stem + knot bend +
#: residual"`` hypothesis, :func:`woodcam.inference.knots.knot_bend_recipes`) needs: the
#: residual is a thin plate fitted on the faces, and with three faces meeting at a corner it
#: extrapolates over the three unseen ones, where its folds (two faces each) cannot judge it.
#: Knotted blocks, noisy traces, within 1 / 2 mm, FIT_VERSION 14 -> with it on three faces:
#: seed 35089 47.6 / 62.4 -> 48.9 / 63.7, 60661 46.6 / 62.0 -> 46.6 / 62.0, 73939 47.0 / 62.4 ->
#: 43.6 / 61.5 (block 15: 96.7 -> 83.5 within 2 mm); with six faces it gains on all three.
KNOT_BEND_RESIDUAL_MIN_FACES = 4

#: The joint fit keeps the plain stem when more than this share of the rings have a growth time
#: at or below the fitted pith's: seed 003's bend is a share of the time since the pith, which
#: such a stem (its "pith" beyond the rings' far side, density negative) does not give; dev
#: seed 21 block 1 with its back face held out diverged to 40-108 years of "bend".
KNOT_BEND_MAX_BEFORE_PITH = 0.02

#: Dead-knot test of a knot exit (:func:`woodcam.inference.knots.exit_is_dead`): the boundary
#: is cut into this many angular sectors around the exit's centroid...
DEAD_KNOT_SECTORS = 16
#: ... each compares three bands of signed distance (mm, negative inside the mask): the bark
#: ring just inside the boundary, the knot wood further in, the stem wood just outside (a
#: dead knot's bark ring is ~0.5 mm a side in woodcam's generator and in seed 003) ...
DEAD_KNOT_BANDS_MM = ((-0.5, 0.0), (-1.2, -0.6), (0.2, 0.8))
#: ... and the exit is dead when at least this share of the sectors is darker in the ring
#: band than on both sides. Measured (16 sectors): synthetic dead knots 15+ mm past their death
#: 0.75-1.0, alive knots 0.0-0.19, H11's knot on C and F 0.0; a knot a few mm past its death,
#: whose bark ring the generator is still blending in, 0.0-0.19 (alive to this test).
DEAD_KNOT_MIN_OUTLINED = 0.5

#: Stem model (``woodcam.inference.stem``, issue 12 part 2). Its priors are Gaussian, weighted
#: as if every fitted ring point carried them with this misfit (years): about the rms misfit of
#: jittered traces (0.3 mm on 1.5-6 mm rings), so a prior one standard deviation off costs as
#: much as the traces' own noise.
STEM_PRIOR_YEARS = 0.3

#: Standard deviation (degrees) of the pith's tilt from the nearest block axis: sawn wood has
#: its grain along the board (slope of grain of a few degrees; the benchmark draws N(0, 2)
#: clipped at 6 for logs, up to 20 for the eq. 7-9 family). Without it, three faces let a
#: pith 45 degrees off fit as well as the true one (seed 21 dev blocks).
STEM_TILT_PRIOR_DEG = 8.0

#: Standard deviation (mm) of the centreline's sagitta over half the block diagonal: generated
#: logs bend by < 0.6 mm over 45 mm (eight logs: median 0.1 mm); 6 mm lets a crooked stem
#: (sagitta 2 mm over 30 mm, tests) bend without letting three noisy faces bend every pith.
STEM_CURVE_PRIOR_MM = 6.0

#: Prior standard deviations of the stem's ring-density terms, as fractions of the mean ring
#: density: azimuthal harmonic k (eccentricity, lobes, speed per azimuth) STEM_HARMONIC_SD / k;
#: change along the stem over half the diagonal STEM_AXIAL_SD; ring width over rho_0 (the
#: ``rho`` powers) STEM_RADIAL_SD. The generator's logs stay inside them (eccentricity <= 0.15,
#: lobes <= 0.025, width slope <= 0.003 / mm over ~100 mm).
STEM_HARMONIC_SD = 0.15
STEM_AXIAL_SD = 0.2
STEM_RADIAL_SD = 0.3

#: Longest step (image pixels) between the points a curved SVG ring trace (cubic, quadratic,
#: arc) is sampled at. A circular arc of radius r sampled every s pixels strays s^2 / (8 r) from
#: its chord: 0.003 px for s = 0.5 and a ring of radius 10 px, far below a ring map's 1 px.
SVG_CURVE_STEP_PX = 0.5

#: Resolutions (dpi) a file states without having been measured: cameras write 72 dpi into
#: EXIF (a phone JPEG's placeholder), editors 72 or 96 (GIMP's PNG pHYs of 2835 px/m reads
#: back as 72.009 dpi, 3780 px/m as 96.012). A veneer file stating one of them states no
#: resolution: taken as the scan's, a phone photo of a sheet would be sized ~4x too large.
DPI_PLACEHOLDERS = (72.0, 96.0)

#: How far (dpi) a stated resolution may be from a placeholder and still be one: the metric
#: rounding of PNG pHYs (2835 px/m = 72.009 dpi) and of a JPEG density in dots/cm (28/cm =
#: 71.12 dpi, 38/cm = 96.52 dpi); a scanner's own settings (75, 100, 150 dpi) are well outside.
DPI_PLACEHOLDER_TOL = 1.0

#: Largest |coordinate| (mm) of a point a growth field is asked about
#: (:func:`woodcam.fields.base.check_points`): 1e6 mm = 1 km, 100 times the longest block
#: (``limits.MAX_BLOCK_SIZE_MM``) and 10 times the farthest ``--start`` or ``--block-centre``,
#: so no real point comes near it, while the fields' powers of a radius stay finite. Points at
#: 1e200 mm overflowed there: an analytic field answered inf years, a knotted one numpy's
#: overflow RuntimeWarning. Not 1e9 mm: a knotted log's time grows with the distance along its
#: axis (17 s for one point at 1e9 mm, 0.02 s at 1e6). A point that far is a unit or frame
#: mistake, refused at the door.
POINT_BOUND_MM = 1e6

#: A mesh grown alone (``woodcam woodify``: no block to compare it with) whose longest side is
#: under this many mm, yet 1 mm or more (under that it looks saved in metres,
#: :data:`woodcam.frames.FOREIGN_GLTF_METRES_BELOW`), is warned about as looking saved in inches
#: (:func:`woodcam.cad.carve.units_hint`): 6.35 mm is the width of a 1/4-inch router bit, the
#: common one, so nothing that short is a part a router carves round, while 25.4 times it (up to
#: 161 mm) is a bowl, a spoon or a handle. A 4-inch bowl saved in inches was read as a 4 mm
#: speck and grown without a word. Not higher: the woodify tests and examples grow 10 mm balls
#: as real millimetre parts, and a 10 mm knob is one.
INCHES_BELOW_MM = 6.35

#: Largest ``|length - 1|`` of a direction taken as unit already (:func:`woodcam._checks.check_vector`
#: with ``unit=True``): returned as given, not divided by its length again. A float64 3-vector
#: divided by its own length lies within 3.4e-16 of length 1 (2e5 random vectors of lengths
#: 1e-8..1e8, some on an axis or nearly), and dividing again moved its last bits:
#: ``GrowthSpeed.from_dict(g.to_dict())`` differed from ``g`` for 692 of 2000 random ``up``.
#: Four times that worst case; a direction this close to unit turns by under 1e-15 rad if kept.
UNIT_LENGTH_TOL = 1.5e-15
