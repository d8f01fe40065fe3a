"""Private test helpers: an eq. 7-9 growth field (seed 000) and blocks traced from it.

Until ``woodcam.fields.radial`` and ``woodcam.synth`` land on main, the tests build their own
synthetic truth here: two smooth periodic radius functions r_-1(phi), r_1(phi) from 15 N(1, 0.1)
constraints, blended linearly along the pith axis (eq. 9), years = rho / (ring_width * r')
(eq. 8), the pith axis placed by a rigid LogFrame (possibly outside the block). Faces are traced
as integer iso-lines of the true field with contourpy.
"""

from __future__ import annotations

import numpy as np
from scipy.interpolate import CubicSpline

from woodcam.block import Block, Face, RingTrace
from woodcam.fields import LogFrame
from woodcam.fields.radial import random_log_frame
from woodcam.frames import FACES, face_image_size_mm, face_pixel_points


class Eq79Field:
    """years = rho / (ring_width_mm * r'(phi, z)), eq. 7-9 of seed 000, in the block frame."""

    def __init__(self, frame: LogFrame, ring_width_mm: float, half_length_mm: float, r_m1, r_p1):
        self.frame, self.w, self.L = frame, ring_width_mm, half_length_mm
        self.r_m1, self.r_p1 = r_m1, r_p1
        self.axis = np.asarray(frame.axis, float) / np.linalg.norm(frame.axis)

    def __call__(self, points_mm):
        q = self.frame.to_log(np.asarray(points_mm, float))
        rho = np.hypot(q[:, 0], q[:, 1])
        phi = np.arctan2(q[:, 0], q[:, 1])  # angle from (0, 1), as in eq. 7
        t = (q[:, 2] / self.L + 1) / 2
        r = np.maximum((1 - t) * self.r_m1(phi) + t * self.r_p1(phi), 0.05)
        return rho / (self.w * r)


def _radius_function(rng, n_c: int = 15):
    ang = np.linspace(0, 2 * np.pi, n_c + 1)
    val = rng.normal(1.0, 0.1, n_c)
    cs = CubicSpline(ang, np.append(val, val[0]), bc_type="periodic")
    return lambda phi: cs(np.mod(phi, 2 * np.pi))


def random_field(rng, size_mm=(50.0, 50.0, 50.0)) -> Eq79Field:
    """An eq. 7-9 field: rings 2-5 mm wide, pith axis tilted <= 20 deg from a random block axis,
    passing 0-60 mm from the block centre (so often outside the block)."""
    frame = random_log_frame(rng, size_mm)
    return Eq79Field(frame, rng.uniform(2, 5), 50.0, _radius_function(rng), _radius_function(rng))


def make_block(field, size_mm=(50.0, 50.0, 50.0), px_per_mm: float = 5.0, rng=None,
               labelled: bool = True, jitter_mm: float = 0.0, missing: float = 0.0,
               n_mislabelled: int = 0, ring_map: bool = False, traces: bool = True,
               segment_mm: float = 10.0, faces=FACES, year_offset: int = 0,
               knot_masks: bool = False) -> Block:
    """Trace the integer iso-lines of ``field`` on the block's faces.

    jitter_mm : std of i.i.d. Gaussian noise added to trace vertices.
    missing : share of ~segment_mm long ring segments dropped.
    n_mislabelled : number of traces whose year label is moved by +-1.
    ring_map : also render a ring map (bright within ~0.15 mm of a ring boundary).
    year_offset : added to every label (a tentative age, as in seed 000 section 3.2.3).
    knot_masks : for a knotted field (``knot_features``), mark each face's knots in
        ``extras["knot_mask"]`` (knot weight > 0.5), as a tracer marks the knots on a photo.
    """
    import contourpy

    rng = np.random.default_rng(0) if rng is None else rng
    out = {}
    for name in faces:
        h, w = face_image_size_mm(name, size_mm)
        shape = (int(round(h * px_per_mm)), int(round(w * px_per_mm)))
        g = field(face_pixel_points(name, shape, size_mm).reshape(-1, 3)).reshape(shape)
        tr = []
        if traces:
            gen = contourpy.contour_generator(z=g, line_type=contourpy.LineType.Separate)
            for year in range(int(np.ceil(g.min())), int(np.floor(g.max())) + 1):
                for line in gen.lines(year):
                    pts = line[:, ::-1]  # contourpy gives (x=col, y=row)
                    pieces = [pts]
                    if missing > 0:
                        step = segment_mm * px_per_mm
                        seg = np.linalg.norm(np.diff(pts, axis=0), axis=1)
                        s = np.concatenate([[0], np.cumsum(seg)])
                        idx = np.floor(s / step).astype(int)
                        keep = rng.random(idx.max() + 1) >= missing
                        pieces = [pts[idx == i] for i in np.flatnonzero(keep)]
                    for p in pieces:
                        if len(p) < 2:
                            continue
                        if jitter_mm > 0:
                            p = p + rng.normal(0, jitter_mm * px_per_mm, p.shape)
                        tr.append(RingTrace(p, year + year_offset if labelled else None))
        rm = None
        if ring_map:
            gr, gc = np.gradient(g)
            grad = np.hypot(gr, gc) * px_per_mm  # years per mm
            d = np.abs(g - np.round(g)) / np.maximum(grad, 1e-9)
            rm = np.exp(-0.5 * (d / 0.15) ** 2).astype(np.float32)
        extras = {}
        if knot_masks:
            pts = face_pixel_points(name, shape, size_mm).reshape(-1, 3)
            extras["knot_mask"] = (field.knot_features(pts)["knot"] > 0.5).reshape(shape)
        out[name] = Face(name, shape, traces=tr, ring_map=rm, extras=extras)
    if n_mislabelled and labelled:
        all_tr = [(n, i) for n in out for i in range(len(out[n].traces))]
        for k in rng.choice(len(all_tr), min(n_mislabelled, len(all_tr)), replace=False):
            n, i = all_tr[k]
            t = out[n].traces[i]
            out[n].traces[i] = RingTrace(t.points_px, t.year + int(rng.choice([-1, 1])))
    return Block(tuple(size_mm), out, true_field=field, name="eq79")
