"""Swept-tool envelopes min-updated into the height field by numba, for every tool profile of
:mod:`woodcam.toolpath.tools`: ball and flat end mills and the V-bit in closed form, the bull
nose on ramps by a bracketed Newton solve of its contact quartic (the formulas of each tool's
:meth:`~woodcam.toolpath.tools.Tool._sweep`, in float64), the snub-nose V-bit / chamfer mill
and tapered ball in closed form too (the V-bit's tangent point, or the flat tip's downhill
edge / the tip sphere's tangent point where the minimum lies there).

The numpy path (:meth:`woodcam.toolpath.tools.Tool._sweep` over ``(moves, wy, wx)`` windows,
then one Python slice update per move) builds four float32 temporaries per window cell and
spent ~0.8 of the 20,000-move raster's whole-run CPU seconds; here each cell's envelope is
computed and applied in one pass. The reach check's replay (:mod:`woodcam.toolpath.reach`)
cuts a few moves at a time, where numpy's per-call cost dominated: a V-bit cost 4.8x a flat
mill there, a bull nose 24x. Tools of other types (a subclass may change the profile) keep
the numpy path. This module imports only numpy and numba.

Conventions as :func:`woodcam.toolpath.simulate._sweep_batch`: ``hm : (ny, nx)`` block-frame Z
(mm) at cell centres, ``a, b : (n, 3)`` tip positions (mm) of the moves, each move's window the
``wy x wx`` cells from ``(js, is_)``. A profile is ``kind`` and ``prm : (4,)`` float64 (mm,
unused entries 0): BALL, FLAT (none); VBIT ``(k)``, ``k = 1 / tan(angle / 2)``; BULL ``(rc)``
corner radius; SNUB ``(rt, k)`` flat tip radius and cone slope; TAPERBALL ``(rb, rt, ht, k)``
ball radius, radius and height where the ball meets the cone, cone slope.
"""

from __future__ import annotations

import math

import numba
import numpy as np

BALL, FLAT, VBIT, BULL, SNUB, TAPERBALL = 0, 1, 2, 3, 4, 5


@numba.njit(nogil=True, cache=True, inline="always")
def _h(kind, prm, R, r):
    """Profile height (mm) above the tip at radius ``r <= R`` of BULL, SNUB and TAPERBALL."""
    if kind == BULL:
        rc = prm[0]
        q = max(r - (R - rc), 0.0)
        return rc - math.sqrt(max(rc * rc - q * q, 0.0))
    if kind == SNUB:
        return prm[1] * max(r - prm[0], 0.0)
    rb, rt, ht, k = prm[0], prm[1], prm[2], prm[3]  # TAPERBALL
    if r <= rt:
        return rb - math.sqrt(max(rb * rb - r * r, 0.0))
    return ht + k * (r - rt)


@numba.njit(nogil=True, cache=True, inline="always")
def _bull_reach(rc, R, s, d):
    """``|w|`` (mm) of the bull nose's lowest point over a cell at distance ``d <= R`` from a
    move's line of slope ``s > 0``: the minimiser of ``-s |w| + h(sqrt(d^2 + w^2))`` (the
    ramp's climb against the profile), unclipped to the chord.

    The contact lies on the torus (on the flat the profile has no slope to meet the ramp's), at
    ``u = sin(phi)``, ``phi`` the contact normal's angle from the axis: ``rho = a + rc u``
    (``a = R - rc``) and ``tan(phi) sqrt(rho^2 - d^2) / rho = s``, which squared is the quartic
    ``F(u) = rho^2 (u^2 (1 + s^2) - s^2) - d^2 u^2 = 0``. Its root in ``[u0, 1]`` (``u0``: where
    ``rho = d``, or 0) is the only one there (the left side rises with u), ``F(u0) <= 0 <=
    F(1) = R^2 - d^2``: a Newton solve kept in that bracket (bisection where a step leaves it)
    takes ~5 steps where the bisection on ``t`` took 30."""
    a = R - rc
    s2 = s * s
    d2 = d * d
    lo = max((d - a) / rc, 0.0) if rc > 0 else 1.0
    hi = 1.0
    # start at the ball's contact (sin of the ramp's angle), which a centred cell (d <= a) nears:
    # 5 steps on average over random cells and slopes, where the bracket's middle took 7
    u = max(lo, s / math.sqrt(1.0 + s2))
    for _ in range(60):
        rho = a + rc * u
        q = u * u * (1.0 + s2) - s2
        f = rho * rho * q - d2 * u * u
        if f > 0:
            hi = u
        else:
            lo = u
        df = 2.0 * rc * rho * q + rho * rho * 2.0 * u * (1.0 + s2) - 2.0 * d2 * u
        un = u - f / df if df > 0 else -1.0
        if not lo < un < hi:  # Newton leaves the bracket: halve it
            un = 0.5 * (lo + hi)
        # 1e-9 in u moves the contact ~1e-9 rc: the height, stationary there, by far less
        if abs(un - u) < 1e-9 or hi - lo < 1e-9:
            u = un
            break
        u = un
    rho = a + rc * u
    return math.sqrt(max(rho * rho - d2, 0.0))


@numba.njit(nogil=True, cache=True)
def sweep_update(hm, line_map, track, kind, prm, R, a, b, js, is_, wy, wx, dx, dy, lines,
                 depth):
    """Min-update ``hm`` with the envelopes of the ``n`` moves; ``depth[k]`` gets how far move
    ``k`` reaches below the stock it meets (``max(hm - envelope)`` over its covered cells,
    before its own update, exact where it is > 0 (BULL: an upper bound <= 0 where
    the move cuts nothing); ``-inf`` if it covers none); with ``track`` the cells a move lowers
    get its source line in ``line_map``. Returns the number of covered cells."""
    covered = 0
    R2 = R * R
    for k in range(a.shape[0]):
        ax, ay, az = a[k, 0], a[k, 1], a[k, 2]
        ex, ey, ez = b[k, 0] - ax, b[k, 1] - ay, b[k, 2] - az
        L = math.hypot(ex, ey)
        if L < 1e-9:  # vertical move: along = x, clipped to t = 0 below, so rho = |cell - p|
            ux, uy, s, z0, L = 1.0, 0.0, 0.0, min(az, b[k, 2]), 0.0
        else:
            ux, uy, s, z0 = ex / L, ey / L, ez / L, az
        tilt = s / math.sqrt(1.0 + s * s)
        # V-bit: the cone's tangent point w = -s d / sqrt(k^2 - s^2) for a move shallower
        # than the cone, else the end of the chord (as VBit._sweep)
        kv = prm[0]
        steep = abs(s) >= kv
        cone = s / math.sqrt(max(kv * kv - s * s, 1e-30))
        deepest = -np.inf
        for jj in range(wy):
            j = js[k] + jj
            cy = (j + 0.5) * dy - ay
            for ii in range(wx):
                i = is_[k] + ii
                cx = (i + 0.5) * dx - ax
                along = cx * ux + cy * uy
                perp = cx * uy - cy * ux
                d2 = perp * perp
                re2 = R2 - d2
                if kind == BALL:
                    # sphere centre on the line: tangent at w = -s Re / sqrt(1 + s^2)
                    re = math.sqrt(max(re2, 0.0))
                    t = min(max(along - tilt * re, 0.0), L)
                    w = t - along
                    q = re2 - w * w
                    if q < 0:
                        continue
                    env = (z0 + R) + s * t - math.sqrt(q)
                else:
                    # the chord |t - along| <= Re, t in [0, L], of the cells the tool covers
                    if re2 < 0:
                        continue
                    re = math.sqrt(re2)
                    lo = max(along - re, 0.0)
                    hi = min(along + re, L)
                    if lo > hi:
                        continue
                    if kind == FLAT:  # the flat bottom: the chord's lowest end
                        env = z0 + s * (lo if s > 0 else hi)
                    elif kind == VBIT:
                        if steep:
                            t = lo if s > 0 else hi
                        else:
                            t = min(max(along - cone * abs(perp), lo), hi)
                        w = t - along
                        env = z0 + s * t + kv * math.sqrt(d2 + w * w)
                    elif kind == SNUB or kind == TAPERBALL:
                        # closed form (as the V-bit's, the profile convex and C1 but for the
                        # snub's kink): the minimiser of s w + h(sqrt(d2 + w^2)), clipped
                        kc = prm[1] if kind == SNUB else prm[3]
                        if abs(s) >= kc:  # steeper than the cone: the chord's lower end
                            t = lo if s > 0 else hi
                        else:
                            d = abs(perp)
                            w = -s * d / math.sqrt(kc * kc - s * s)  # on the cone
                            if kind == SNUB:
                                rt = prm[0]
                                if d * d + w * w < rt * rt:  # on the flat: its downhill edge
                                    wf = math.sqrt(max(rt * rt - d2, 0.0))
                                    w = -wf if s > 0 else (wf if s < 0 else 0.0)
                            elif d < prm[1]:  # the tip's sphere, where it holds the minimum
                                wb = -s * math.sqrt(max(prm[0] * prm[0] - d2, 0.0)) / math.sqrt(
                                    1.0 + s * s)
                                if d2 + wb * wb <= prm[1] * prm[1]:
                                    w = wb
                            t = min(max(along + w, lo), hi)
                        w = t - along
                        env = z0 + s * t + _h(kind, prm, R, min(math.sqrt(d2 + w * w), R))
                    else:  # BULL
                        # the envelope is at least the chord's lowest tip plus the profile at
                        # the cell's distance from the line: a cell that bound leaves
                        # untouched (most of a raster's overlap with the last pass) needs no
                        # solve (its depth, <= 0, is said as cur - bound >= cur - env)
                        bound = z0 + min(s * lo, s * hi) + _h(kind, prm, R, min(abs(perp), R))
                        if bound >= hm[j, i]:
                            covered += 1
                            if hm[j, i] - bound > deepest:
                                deepest = hm[j, i] - bound
                            continue
                        # convex in t: the unclipped minimiser (_bull_reach, downhill of the
                        # foot of the perpendicular), clipped to the chord
                        if s != 0.0:
                            w = _bull_reach(prm[0], R, abs(s), min(abs(perp), R))
                            t = min(max(along - w if s > 0 else along + w, lo), hi)
                        else:  # horizontal: the foot of the perpendicular (even in w)
                            t = min(max(along, lo), hi)
                        w = t - along
                        env = z0 + s * t + _h(kind, prm, R, min(math.sqrt(d2 + w * w), R))
                covered += 1
                cur = hm[j, i]
                if cur - env > deepest:
                    deepest = cur - env
                if env < cur:
                    hm[j, i] = env
                    if track:
                        line_map[j, i] = lines[k]
        depth[k] = deepest
    return covered
