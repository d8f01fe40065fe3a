"""Compiled (numba) kernel of :class:`woodcam.fields.knots.KnottedLogField`.

Same formulas as the numpy path of ``KnottedLogField._eval_chunk`` (seed 003 eqs. 1-6, see
``knots.py``), one pass per point over the chunk's candidate knots. It is hand-written as a loop
because the numpy path must materialise ~40 (knots x points) temporaries, while a point
typically lies inside the distance range of only a few of its candidate knots: the loop skips
the others after two table look-ups, which is where the ~20x speed-up comes from. Imported only
when the numba backend is used.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit, prange

_EPS = 1e-9
_L = 100.0  # the seed shader's time unit in mm of stem radius (knot darkening)


@njit(cache=True, inline="always")
def _delta(ts, tb, k):
    mn = min(ts, tb)
    mx = max(max(ts, tb), _EPS)
    q = mn / mx
    if q <= 0.0:
        return 0.0, mn
    return mn * math.expm1(-math.log1p(math.exp(k * math.log(q))) / k), mn


@njit(parallel=True, cache=True)
def eval_points(pts, zg0, inv_dz, pxy, speed, bin_z0, inv_bw, bin_ptr, bin_knots,
                r_end, r_death, Zf, CWf, SWf, Rf, nr1, inv_dr, phase, prm, out, best):
    """Whole field at log-frame points ``pts (m, 3)``.

    Stem: pith ``pxy (nz, 2)`` and relative speed ``speed (nz, a)`` on a regular height grid
    (``zg0``, ``1 / inv_dz``), linear in height, periodic-linear in azimuth. Knots: point ``i``
    visits the knots listed for its height bin (``bin_ptr``/``bin_knots``, CSR; bins of width
    ``1 / inv_bw`` from ``bin_z0``). Fills ``out (5, m)`` = (t in mm of stem radius, knot,
    dead, outline, r of the nearest knot) and ``best (m,)`` (nearest knot index or -1).
    """
    k_s, k_b, c_k, rate, f1, f2, f_len, bfly = prm[0], prm[1], prm[2], prm[3], prm[4], prm[5], \
        prm[6], prm[7]
    d0, k0, d1, k1, noise_a, th, sharp = prm[8], prm[9], prm[10], prm[11], prm[12], prm[13], \
        prm[14]
    band = prm[15]
    fr = f2 - f1
    m = pts.shape[0]
    nz = pxy.shape[0]
    na = speed.shape[1]
    nb = bin_ptr.shape[0] - 1
    for i in prange(m):
        zi = pts[i, 2]
        fz = (zi - zg0) * inv_dz
        fz = min(max(fz, 0.0), nz - 1.0)
        iz = int(fz)
        if iz > nz - 2:
            iz = nz - 2
        tz = fz - iz
        dxi = pts[i, 0] - (pxy[iz, 0] + (pxy[iz + 1, 0] - pxy[iz, 0]) * tz)
        dyi = pts[i, 1] - (pxy[iz, 1] + (pxy[iz + 1, 1] - pxy[iz, 1]) * tz)
        dsi = math.sqrt(dxi * dxi + dyi * dyi)
        om = math.atan2(dyi, dxi)
        if om < 0.0:
            om += 2.0 * math.pi
        fa = om * (na / (2.0 * math.pi))
        ia = int(fa)
        ta = fa - ia
        ia = ia % na
        ia1 = (ia + 1) % na
        s0 = speed[iz, ia] + (speed[iz, ia1] - speed[iz, ia]) * ta
        s1 = speed[iz + 1, ia] + (speed[iz + 1, ia1] - speed[iz + 1, ia]) * ta
        spi = s0 + (s1 - s0) * tz
        ts = dsi / spi
        bi = int(min(max((zi - bin_z0) * inv_bw, 0.0), nb - 1.0))
        ce = math.cos(0.05 * dsi)
        se = math.sin(0.05 * dsi)
        tmin = ts
        sumd = 0.0
        inv2 = 0.0
        deadmax = 0.0
        outline = 0.0
        bt = np.inf
        bk = -1
        br = 0.0
        range1 = d1 + k1 * dsi
        range0 = d0 + k0 * dsi
        for jj in range(bin_ptr[bi], bin_ptr[bi + 1]):
            k = bin_knots[jj]
            r = min(dsi, r_end[k])
            fi = r * inv_dr
            i0 = int(fi)
            f = fi - i0
            b = k * nr1 + i0
            zb = Zf[b] + (Zf[b + 1] - Zf[b]) * f
            bz = zi - zb
            if abs(bz) >= range1:
                continue
            cw = CWf[b] + (CWf[b + 1] - CWf[b]) * f
            sw = SWf[b] + (SWf[b + 1] - SWf[b]) * f
            bx = dxi - r * cw
            by = dyi - r * sw
            db = math.sqrt(bx * bx + by * by + bz * bz)
            if db >= range1:
                continue
            rho = Rf[b] + (Rf[b + 1] - Rf[b]) * f
            tang = by * cw - bx * sw
            hyp = max(math.sqrt(tang * tang + bz * bz), _EPS)
            cb = tang / hyp
            sb = bz / hyp
            if noise_a != 0.0:
                c2 = cb * cb - sb * sb
                s2 = 2.0 * cb * sb
                c3 = c2 * cb - s2 * sb
                s3 = s2 * cb + c2 * sb
                cp3 = phase[k, 2] * ce - phase[k, 5] * se
                sp3 = phase[k, 5] * ce + phase[k, 2] * se
                nzv = (0.5 * (cb * phase[k, 0] + sb * phase[k, 3])
                       + 0.3 * (c2 * phase[k, 1] + s2 * phase[k, 4])
                       + 0.2 * (c3 * cp3 + s3 * sp3))
                rho = rho * (1.0 + noise_a * nzv)
            vb = rho * spi
            tb = db / vb
            tD = ts - tb
            kk = 0.5 * (k_b - k_s) * tD / (c_k + abs(tD)) + 0.5 * (k_b + k_s)
            delta, mn = _delta(ts, tb, kk)
            sm = mn + delta
            Td = r_death[k] / spi
            tb2 = tb
            wd = min(max((sm - Td) / band, 0.0), 1.0)
            wd = wd * wd * (3.0 - 2.0 * wd)
            if wd > 0.0:
                ta = ts - Td
                tb2 = tb + wd * ta
                d2, _ = _delta(ts, tb + ta, kk + rate * ta)
                td2 = ta / f_len - 1.0
                fac = 1.0 - 0.5 * fr * td2 / (0.3 + abs(td2)) + f1 + 0.5 * fr
                fac = 1.0 + (fac - 1.0) * (1.0 - bfly * sb * sb)
                delta = (1.0 - wd) * delta + wd * fac * d2
            prog = (db - range0) / (range1 - range0)
            if prog > 0.0:
                delta *= 1.0 - min(prog, 1.0)
            sumd += delta
            if tb2 < tmin:
                tmin = tb2
            inv2 += 1.0 / (max(tb2, _EPS) * max(tb2, _EPS))
            if tb2 < bt:
                bt = tb2
                bk = k
                br = r
            if tb < Td and ts > Td:
                dv = min(max(6.0 * (ts - Td) / _L, 0.0), 1.0)
                if dv > deadmax:
                    deadmax = dv
            if wd < 1.0 and (tb - Td) * vb < th and r_death[k] < r_end[k]:
                if (Td - sm) * vb <= th:
                    outline = 1.0
        if inv2 > 0.0:
            tsoft = 1.0 / math.sqrt(inv2)
            w = (ts - tsoft) / ts if ts > 0.0 else 0.0
            w = min(max(w, 0.0), 1.0)
            w = w * w * (3.0 - 2.0 * w)
            x = min(max((1.2 * tsoft - ts) / _L, 0.001), 1.0)
            knot = 1.0 / (x + 1.0) ** sharp
        else:
            w = 0.0
            knot = 0.0
        out[0, i] = tmin + (1.0 - w) * sumd
        out[1, i] = knot
        out[2, i] = deadmax * knot
        out[3, i] = outline
        out[4, i] = br
        best[i] = bk
