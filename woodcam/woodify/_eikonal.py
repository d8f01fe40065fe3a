"""Compiled anisotropic fast marching for ``g(x) (|grad T| + w(x) . grad T) = 1`` on a grid.

This is the eccentric growth front of seed 004 (normal speed ``g (1 + w . n)``, sec. 4.2.1)
as a static Hamilton-Jacobi problem: a Randers metric (Zermelo navigation: unit speed in a wind
``w``). scikit-fmm solves only the isotropic eikonal ``|grad T| = 1 / F(x)``; no installed (or,
as far as we know, maintained Python) library solves this anisotropic one with obstacles, so it
is written here.

Scheme: Sethian's fast marching (one heap pass), with the upwind update of each node solved in
closed form on every simplex of accepted axis neighbours (1, 2 or 3 axes; each +-): for the
axes ``S`` used, ``p_d = (T - T_d) / (o_d h)`` (neighbour at ``x + o_d h e_d``) and the unused
components are those that keep the characteristic ``v = p / |p| + w`` inside the simplex
(``p_j = -w_j |p|``), giving one quadratic in ``T``. A solution counts only when its
characteristic points from the neighbours into the node (causality); the smallest valid one
wins. For one axis it is the exact Randers length of the grid step. Along an axis with two
marched (or first-layer) nodes the difference is second order; a start node inside the input
is only ever the near node (see ``SOURCE``). Obstacle nodes never
accept a value, so fronts wrap round them; disjoint fronts merge by the min of the heap.
"""

from __future__ import annotations

import heapq

import numba
import numpy as np

FAR, TRIAL, ACCEPTED, BLOCKED, FIXED, SOURCE = 0, 1, 2, 3, 4, 5
# SOURCE: a start node inside the input, fixed at ``T = -distance``. That is no smooth function
# across the surface (a kink where the nearest face changes: a box's edges, its medial planes),
# so a SOURCE node may be the near node of an update but never the far node of a second-order
# difference: a node on a box's face plane past its edge holds 0, not the -2.7 mm the line
# through it wants, and every node beyond that edge arrived 0.4 of a step early (the box grew
# 0.39 of a step too far at resolution 27).


@numba.njit(cache=True, nogil=True)
def _simplex_update(av, bv, ov, tmax, g, wx, wy, wz, slack):  # pragma: no cover - compiled
    """Smallest causal ``T`` with ``dT/dx_d = av[d] T + bv[d]`` on the axes ``ov[d] != 0``."""
    w = (wx, wy, wz)
    A2 = 0.0
    A1 = 0.0
    A0 = 0.0
    r0 = 1.0 / g
    r1 = 0.0
    wp = 1.0
    for d in range(3):
        if ov[d] == 0:
            wp -= w[d] * w[d]
            continue
        a = av[d]
        b = bv[d]
        A2 += a * a
        A1 += a * b
        A0 += b * b
        r1 -= w[d] * a
        r0 -= w[d] * b
    qa = wp * A2 - r1 * r1
    qb = 2.0 * (wp * A1 - r0 * r1)
    qc = wp * A0 - r0 * r0
    best = np.inf
    if abs(qa) < 1e-14:
        if abs(qb) < 1e-14:
            return best
        roots = (-qc / qb, -qc / qb)
    else:
        disc = qb * qb - 4.0 * qa * qc
        if disc < 0.0:
            return best
        sq = np.sqrt(disc)
        roots = ((-qb + sq) / (2.0 * qa), (-qb - sq) / (2.0 * qa))
    for T in roots:
        if r0 + r1 * T < 0.0 or T < tmax - slack:
            continue
        q = 0.0
        for d in range(3):
            if ov[d] != 0:
                p = av[d] * T + bv[d]
                q += p * p
        pn = np.sqrt(q / wp)
        if pn <= 0.0:
            continue
        ok = True
        for d in range(3):
            if ov[d] != 0:
                v = (av[d] * T + bv[d]) / pn + w[d]
                if -ov[d] * v < -1e-9:
                    ok = False
        if ok and T < best:
            best = T
    return best


@numba.njit(cache=True, nogil=True)
def _node_update(T, state, i, j, k, g, wx, wy, wz, h, order, slack, nb, nb2, av, bv, ov,
                 fix_axis=-1, fix_choice=0):  # pragma: no cover - compiled
    nx, ny, nz = T.shape
    # accepted neighbour values per axis and side (0: at -1, 1: at +1), one and two nodes away
    nb[:] = np.inf  # work buffers passed in: allocating per call dominated the run time
    nb2[:] = np.inf
    idx = (i, j, k)
    n = (nx, ny, nz)
    for d in range(3):
        for s in range(2):
            o = 2 * s - 1
            for step in range(1, order + 1):
                c = idx[d] + o * step
                if c < 0 or c >= n[d]:
                    break
                ii, jj, kk = i, j, k
                if d == 0:
                    ii = c
                elif d == 1:
                    jj = c
                else:
                    kk = c
                st = state[ii, jj, kk]
                if st != ACCEPTED and st != FIXED and (st != SOURCE or step > 1):
                    break
                if step == 1:
                    nb[d, s] = T[ii, jj, kk]
                elif T[ii, jj, kk] <= nb[d, s]:
                    nb2[d, s] = T[ii, jj, kk]
    best = np.inf
    # every non-empty choice of (unused, -1, +1) per axis: 26 simplices
    for cx in range(3):
        for cy in range(3):
            for cz in range(3):
                if cx == 0 and cy == 0 and cz == 0:
                    continue
                choice = (cx, cy, cz)
                # only simplices through the node just accepted can lower the value: the
                # others were tried when their nodes were accepted
                if fix_axis >= 0 and choice[fix_axis] != fix_choice:
                    continue
                ok = True
                tmax = -np.inf
                for d in range(3):
                    ch = choice[d]
                    if ch == 0:
                        ov[d] = 0
                        continue
                    t1 = nb[d, ch - 1]
                    if t1 == np.inf:
                        ok = False
                        break
                    o = 2 * (ch - 1) - 1
                    ov[d] = o
                    t2 = nb2[d, ch - 1]
                    if t2 < np.inf:
                        # second-order one-sided difference (as scikit-fmm's order 2)
                        av[d] = -1.5 * o / h
                        bv[d] = o * (4.0 * t1 - t2) / (2.0 * h)
                    else:
                        av[d] = -o / h
                        bv[d] = o * t1 / h
                    tmax = max(tmax, t1)
                if not ok:
                    continue
                t = _simplex_update(av, bv, ov, tmax, g, wx, wy, wz, slack)
                best = min(best, t)
    return best


@numba.njit(cache=True, nogil=True)
def march(T, state, gain, wind, h, order=2, reopen_tol=1e-3, slack_nodes=1.0):  # pragma: no cover - compiled
    """Fast marching in place. ``T (nx, ny, nz) float64`` holds the accepted start values;
    ``state (nx, ny, nz) int8`` is SOURCE inside the input, FIXED on the first layer outside
    it (exact values), BLOCKED on obstacles, FAR elsewhere.
    ``gain`` is ``(nx, ny, nz)`` or ``(1, 1, 1)`` (constant); ``wind`` ``(.., 3)`` likewise.
    Unreached nodes keep ``inf``."""
    nx, ny, nz = T.shape
    slack = slack_nodes * h
    nb = np.empty((3, 2))
    nb2 = np.empty((3, 2))
    av = np.zeros(3)
    bv = np.zeros(3)
    ov = np.zeros(3, np.int64)
    gconst = gain.shape[0] == 1
    wconst = wind.shape[0] == 1
    heap = [(0.0, 0)]
    heap.pop()
    offs = ((1, 0, 0), (-1, 0, 0), (0, 1, 0), (0, -1, 0), (0, 0, 1), (0, 0, -1))
    for i in range(nx):
        for j in range(ny):
            for k in range(nz):
                if state[i, j, k] != FIXED and state[i, j, k] != SOURCE:
                    continue
                for o in offs:
                    a, b, c = i + o[0], j + o[1], k + o[2]
                    if a < 0 or b < 0 or c < 0 or a >= nx or b >= ny or c >= nz:
                        continue
                    if state[a, b, c] == FAR:
                        state[a, b, c] = TRIAL
                        heapq.heappush(heap, (0.0, (a * ny + b) * nz + c))
    # the first pops only seed the trial values
    seeds = heap
    heap = [(0.0, 0)]
    heap.pop()
    for item in seeds:
        lin = item[1]
        a = lin // (ny * nz)
        b = (lin // nz) % ny
        c = lin % nz
        gi = gain[0, 0, 0] if gconst else gain[a, b, c]
        if wconst:
            t = _node_update(T, state, a, b, c, gi, wind[0, 0, 0, 0], wind[0, 0, 0, 1], wind[0, 0, 0, 2],
                             h, order, slack, nb, nb2, av, bv, ov)
        else:
            t = _node_update(T, state, a, b, c, gi, wind[a, b, c, 0], wind[a, b, c, 1], wind[a, b, c, 2],
                             h, order, slack, nb, nb2, av, bv, ov)
        T[a, b, c] = min(T[a, b, c], t)
        heapq.heappush(heap, (T[a, b, c], lin))
    while len(heap) > 0:
        t0, lin = heapq.heappop(heap)
        i = lin // (ny * nz)
        j = (lin // nz) % ny
        k = lin % nz
        if state[i, j, k] == ACCEPTED or t0 > T[i, j, k]:
            continue
        state[i, j, k] = ACCEPTED
        for o in offs:
            a, b, c = i + o[0], j + o[1], k + o[2]
            if a < 0 or b < 0 or c < 0 or a >= nx or b >= ny or c >= nz:
                continue
            st = state[a, b, c]
            if st == BLOCKED or st == FIXED or st == SOURCE:
                continue
            gi = gain[0, 0, 0] if gconst else gain[a, b, c]
            # the accepted node sits at -o from (a, b, c): axis fa, choice 1 (-1 side) or 2 (+1)
            fa = 0 if o[0] != 0 else (1 if o[1] != 0 else 2)
            fc = 1 if o[fa] > 0 else 2
            if wconst:
                t = _node_update(T, state, a, b, c, gi, wind[0, 0, 0, 0], wind[0, 0, 0, 1], wind[0, 0, 0, 2],
                                 h, order, slack, nb, nb2, av, bv, ov, fa, fc)
            else:
                t = _node_update(T, state, a, b, c, gi, wind[a, b, c, 0], wind[a, b, c, 1], wind[a, b, c, 2],
                                 h, order, slack, nb, nb2, av, bv, ov, fa, fc)
            # an accepted node re-opens when a later neighbour improves it: with anisotropy the
            # characteristic may leave a simplex whose nodes are accepted after it (non-causal
            # for plain fast marching); label-correcting settles it at the same fixed point.
            if t < T[a, b, c] - (reopen_tol * h if st == ACCEPTED else 0.0):
                T[a, b, c] = t
                state[a, b, c] = TRIAL
                heapq.heappush(heap, (t, (a * ny + b) * nz + c))
    return T
