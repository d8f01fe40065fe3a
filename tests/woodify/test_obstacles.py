"""Growth round a rod obstacle (seed 004 sec. 4.2.3): stops on contact, wraps, engulfs; the
field marks the rod as no wood and the rings bend round it. Known answer: in the section the
front reaches the far side of the rod along the shortest path round it (a tangent, then an arc)."""

from __future__ import annotations

import numpy as np
import pytest
import trimesh

from woodcam.woodify import woodify

R0, D, A = 6.0, 14.0, 2.5  # trunk radius, rod axis distance, rod radius (mm)
#: pseudo-time at which the front closes behind the rod: tangent from the trunk axis + arc - r0
TAU_ENGULF = np.sqrt(D ** 2 - A ** 2) + A * (np.pi - np.arccos(A / D)) - R0
TAU_CONTACT = D - A - R0


def _grow(method, eccentricity=0.0):
    trunk = trimesh.creation.cylinder(radius=R0, height=16.0, sections=64)
    rod = trimesh.creation.cylinder(radius=A, height=90.0, sections=48)
    rod.apply_translation((D, 0.0, 0.0))
    return woodify(trunk, 20, growth_mm=16.0, resolution=72, obstacles=[rod], method=method,
                   eccentricity=eccentricity, up=(1.0, 0.0, 0.0))


@pytest.fixture(scope="module", params=["fmm", "anisotropic"])
def grown(request):
    return _grow(request.param)


def _rod_distance(p):
    return np.hypot(p[:, 0] - D, p[:, 1]) - A


def test_no_grown_vertex_inside_the_rod_at_any_year(grown):
    for year in (5.0, 10.0, 15.0, 20.0):
        s = grown.surface(year)
        assert s.is_watertight
        assert _rod_distance(s.vertices).min() >= 0.0, year


def test_front_wraps_and_engulfs_after_the_predicted_year(grown):
    h = grown.front.grid.spacing_mm
    sp = grown.speed
    behind = np.array([[D + A + 0.5 * h, 0.0, 0.0]])
    # the arrival just behind the rod is the geodesic round it (exact answer TAU_ENGULF + 0.5 h).
    # The rod is a set of masked nodes: the front hugs a staircase round it, which measured
    # 1.35-1.4 voxels longer than the arc of the true rod (2 voxels is the bar; the engulf year,
    # the latest arrival on nodes next to the rod, measured 1.9 voxels late).
    T = grown.field.arrival(behind)[0]
    assert -0.5 * h < T - (TAU_ENGULF + 0.5 * h) < 2.0 * h, (T, TAU_ENGULF)
    # not wood before the predicted year, wood soon after it
    assert grown.field(behind)[0] > sp.years(TAU_ENGULF - 0.5 * h)
    assert grown.field(behind)[0] < sp.years(TAU_ENGULF + 2.5 * h)
    # engulfed in the trunk's height range by the predicted year, in voxels of pseudo-time
    t_engulf = grown.engulf_year(0, inside_box=((-50, -50, -4), (50, 50, 4)))
    assert -0.5 * h < sp.tau(t_engulf) - TAU_ENGULF < 2.5 * h
    assert t_engulf > sp.years(TAU_CONTACT + h)


def test_rings_bend_round_the_rod_and_it_is_no_wood(grown):
    h = grown.front.grid.spacing_mm
    f = grown.field
    # far side of the trunk: unobstructed, arrival = distance to the trunk
    free = f.arrival(np.array([[-(D + A + 1.0), 0.0, 0.0]]))[0]
    assert abs(free - (D + A + 1.0 - R0)) < 0.5 * h
    # behind the rod the rings are pushed out (later arrival): they bend round it
    behind = f.arrival(np.array([[D + A + 1.0, 0.0, 0.0]]))[0]
    assert behind - (D + A + 1.0 - R0) > 2 * h
    # a ring line of a year after contact bends: beside the rod it is nearer the trunk than
    # straight behind it
    beside = f.arrival(np.array([[D, A + 1.0, 0.0]]))[0]
    assert beside < behind
    assert f.no_wood(np.array([[D, 0.0, 0.0], [D, 0.0, 30.0]])).all()
    assert not f.no_wood(np.array([[D + A + 1.0, 0.0, 0.0]])).any()
    ev = f.evaluate(np.array([[D, 0.0, 0.0], [0.0, 12.0, 0.0]]), directions=True)
    assert ev["dead"].tolist() == [1.0, 0.0]


def test_eccentric_growth_round_the_rod_stays_outside():
    g = _grow("auto", eccentricity=0.3)
    assert g.front.method == "anisotropic"
    for year in (8.0, 20.0):
        assert _rod_distance(g.surface(year).vertices).min() >= 0.0
    # faster towards +X (the rod side): the wood closes behind the rod sooner than without
    h = g.front.grid.spacing_mm
    T = g.field.arrival(np.array([[D + A + 0.5 * h, 0.0, 0.0]]))[0]
    assert T < TAU_ENGULF
