"""Bark: cracks from hoop stress run along a growing cylinder; texture and attributes carried from
the input stay put; brushes speed growth up where painted."""

from __future__ import annotations

import numpy as np
import pytest
import trimesh

from woodcam.errors import WoodcamError
from woodcam.woodify import Brush, woodify
from woodcam.woodify.cracks import growth_stress, separation, separation_local, simulate_cracks
from woodcam.woodify.surfaces import barycentric_on, carry, trace_back, trace_grids


@pytest.fixture(scope="module")
def cylinder():
    cyl = trimesh.creation.cylinder(radius=8.0, height=60.0, sections=64)
    return woodify(cyl, 5, growth_mm=6.0, resolution=64)


def _edge_dirs(cs, lateral_half_height=22.0):
    v = cs.mesh.vertices
    e = v[cs.crack_edges[:, 1]] - v[cs.crack_edges[:, 0]]
    e /= np.linalg.norm(e, axis=1, keepdims=True)
    mid = v[cs.crack_edges].mean(1)
    return e[np.abs(mid[:, 2]) < lateral_half_height]


def test_hoop_stress_of_a_growing_cylinder_is_circumferential(cylinder):
    mesh = cylinder.surface(4.0)
    old, _ = trace_back(cylinder.front, mesh.vertices, until_mm=cylinder.tau(3.0))
    sig = growth_stress(mesh, old)
    c = mesh.triangles_center
    lat = np.abs(c[:, 2]) < 20
    hoop = np.stack([-c[:, 1], c[:, 0], np.zeros(len(c))], 1)
    hoop /= np.linalg.norm(hoop, axis=1, keepdims=True)
    s_hoop = np.einsum("fi,fij,fj->f", hoop, sig, hoop)[lat]
    s_axial = sig[lat, 2, 2]
    r3, r4 = 8.0 + cylinder.tau(3.0), 8.0 + cylinder.tau(4.0)
    expect = 0.5 * ((r4 / r3) ** 2 - 1)  # Green-type stretch of the circumference
    assert np.median(s_hoop) == pytest.approx(expect, rel=0.15)
    assert np.median(np.abs(s_axial)) < 0.1 * expect
    zeta = separation(mesh, sig)
    _, V = np.linalg.eigh(zeta)
    vl = np.abs(mesh.vertices[:, 2]) < 20
    e = V[vl, :, -1]
    hv = np.stack([-mesh.vertices[vl, 1], mesh.vertices[vl, 0], 0 * mesh.vertices[vl, 0]], 1)
    hv /= np.linalg.norm(hv, axis=1, keepdims=True)
    assert np.median(np.abs(np.sum(e * hv, 1))) > 0.95  # opening across the circumference


def _grids_from_scratch(front):
    """The back-trace grids as trace_back built them on every call before they were cached."""
    T = np.where(np.isfinite(front.arrival_mm), front.arrival_mm, np.nan)
    Tf = np.where(np.isnan(T), np.nanmax(T), T)
    return Tf.astype(np.float32), [g.astype(np.float32) for g in np.gradient(Tf, front.grid.spacing_mm)]


def test_trace_back_grids_are_built_once_per_front_and_never_shared(cylinder):
    import dataclasses

    a = dataclasses.replace(cylinder.front)  # own cache, the module fixture stays untouched
    # a second front on the same grid: a different growth, so different grids and origins
    b = dataclasses.replace(a, arrival_mm=np.where(a.arrival_mm > 0, a.arrival_mm * 1.3, a.arrival_mm))
    pts = cylinder.surface(4.0).vertices
    ra, _ = trace_back(a, pts, until_mm=cylinder.tau(2.0))
    assert trace_grids(a)[1][0] is trace_grids(a)[1][0]  # kept, not rebuilt
    rb, _ = trace_back(b, pts, until_mm=cylinder.tau(2.0))
    assert np.abs(ra - rb).max() > 0.1 * cylinder.front.grid.spacing_mm
    for front in (a, b):  # the same bytes as the per-call grids of the old code
        T, grads, t_max = trace_grids(front)
        T0, grads0 = _grids_from_scratch(front)
        assert t_max == np.nanmax(np.where(np.isfinite(front.arrival_mm), front.arrival_mm, np.nan))
        assert T.dtype == np.float32 and np.array_equal(T, T0)
        assert all(np.array_equal(g, g0) for g, g0 in zip(grads, grads0))
    rb_fresh, _ = trace_back(dataclasses.replace(b), pts, until_mm=cylinder.tau(2.0))
    assert np.array_equal(rb, rb_fresh)
    assert np.array_equal(trace_back(a, pts, until_mm=cylinder.tau(2.0))[0], ra)
    # a new arrival array on the same front rebuilds the grids
    a.arrival_mm = b.arrival_mm.copy()
    assert np.array_equal(trace_back(a, pts, until_mm=cylinder.tau(2.0))[0], rb)


def _map_coordinates4(g0, g1, g2, g3, q):
    """What trace_back did before sample_linear4: one scipy call per grid."""
    from scipy import ndimage

    return np.stack([ndimage.map_coordinates(g, q.T, order=1, mode="nearest") for g in (g0, g1, g2, g3)])


def test_sample_linear4_is_scipys_map_coordinates_bit_for_bit():
    """The back-trace samples the arrival time and its gradient in one pass instead of four
    map_coordinates calls: the same float32 bits, also at and beyond the grid's faces."""
    from woodcam.woodify._voxel import sample_linear4

    rng = np.random.default_rng(0)
    grids = [rng.standard_normal((9, 12, 15)).astype(np.float32) for _ in range(4)]
    q = rng.uniform(-2.0, 17.0, (20000, 3))
    q[:3000] = np.round(q[:3000])                     # on nodes, the last ones included
    q[3000:3500, 0] = 8.0                             # on the last x face
    q[3500:4000] = rng.uniform(-0.5, 0.5, (500, 3))   # round the first corner
    assert np.array_equal(sample_linear4(*grids, q).view(np.uint32),
                          _map_coordinates4(*grids, q).view(np.uint32))


def test_cracks_are_the_same_bytes_as_with_map_coordinates(cylinder, monkeypatch):
    """The crack stage's back-traces through sample_linear4 give the cracks, stress and origins
    that four map_coordinates calls a step gave (at resolution 200 the stage took 0.75 of the
    time, in the same run)."""
    from woodcam.woodify import _voxel

    new = simulate_cracks(cylinder, [2, 3, 4, 5])
    monkeypatch.setattr(_voxel, "sample_linear4", _map_coordinates4)
    old = simulate_cracks(cylinder, [2, 3, 4, 5])
    assert len(new.crack_directions) > 5
    for name in ("crack_edges", "crack_width", "origins_mm", "tri", "stress", "crack_points"):
        assert np.array_equal(getattr(new, name), getattr(old, name)), name


def test_separation_after_a_relief_is_that_of_the_faces_round_the_vertices(cylinder):
    from scipy.spatial import cKDTree

    mesh = cylinder.surface(4.0)
    old, _ = trace_back(cylinder.front, mesh.vertices, until_mm=cylinder.tau(3.0))
    sig = growth_stress(mesh, old)
    ring = np.array([5, 17, 400, 401, 1200, 3])
    # the old way: a submesh of those faces, its vertices found again by position
    vf = mesh.vertex_faces[ring]
    faces = np.unique(vf[vf >= 0])
    sub = mesh.submesh([faces], append=True, repair=False)
    _, j = cKDTree(sub.vertices).query(mesh.vertices[ring])
    expect = separation(sub, sig[faces])[j]
    assert np.array_equal(separation_local(mesh, sig, ring), expect)
    assert np.allclose(expect, separation(mesh, sig)[ring], rtol=1e-12, atol=1e-15)


def test_separation_local_reads_only_the_faces_round_the_vertices(cylinder, monkeypatch):
    """separation_local read the whole surface per call (neighbour lists, frames, vertex normals
    and faces of every vertex) for the few faces round its vertices: now only those faces, with
    the crack loop's read-once result to the bit."""
    from woodcam.woodify import cracks

    src = cylinder.surface(4.0)
    old, _ = trace_back(cylinder.front, src.vertices, until_mm=cylinder.tau(3.0))
    sig = growth_stress(src, old)
    whole = cracks._MeshArrays.of(src)
    rings = [np.array([5, 17, 400, 401, 1200, 3]), np.array([], int), np.arange(len(src.vertices)),
             np.array([7, 7, 2])]

    def read_once(ring):  # as the crack loop does it, from its read-once arrays
        vf = whole.vertex_faces[ring]
        f = np.unique(vf[vf >= 0])
        return cracks._separation_round(whole.faces[f], whole.tri[f], whole.area[f], whole.face_normals[f], sig[f],
                                        ring)

    expect = [read_once(r) for r in rings]

    def whole_read(*_):
        raise AssertionError("the whole surface was read")

    monkeypatch.setattr(cracks, "_neighbours", whole_read)
    monkeypatch.setattr(cracks._MeshArrays, "of", whole_read)
    mesh = trimesh.Trimesh(src.vertices.copy(), src.faces.copy(), process=False)  # nothing cached
    for ring, z in zip(rings, expect):
        assert np.array_equal(separation_local(mesh, sig, ring), z)
    assert "vertex_faces" not in mesh._cache.cache and "vertex_normals" not in mesh._cache.cache


def test_a_crack_year_frames_its_faces_once(cylinder, monkeypatch):
    """The crack loop read a year's face frames into its arrays, then growth_stress computed the
    same frames again from the mesh: now the loop hands its frames over, once per year for the
    surface and once for last year's corners, and the stress is growth_stress's to the bit."""
    from woodcam.woodify import cracks

    mesh = cylinder.surface(4.0)
    old, _ = trace_back(cylinder.front, mesh.vertices, until_mm=cylinder.tau(3.0))
    ma = cracks._MeshArrays.of(mesh)
    # the reference: growth_stress from the mesh itself
    assert np.array_equal(cracks._growth_stress(ma.frames, ma.tri, old[ma.faces]), growth_stress(mesh, old))
    # the frames: orthonormal columns in each face's plane (trimesh's face normals), to 1e-9
    gram = np.einsum("fdk,fdl->fkl", ma.frames, ma.frames)
    assert np.allclose(gram, np.eye(2), atol=1e-9)
    assert np.abs(np.einsum("fdk,fd->fk", ma.frames, mesh.face_normals)).max() < 1e-9
    calls = []
    real = cracks._frames_of
    monkeypatch.setattr(cracks, "_frames_of", lambda tri: calls.append(len(tri)) or real(tri))
    simulate_cracks(cylinder, [2, 3, 4, 5])
    faces = [len(cylinder.surface(y).faces) for y in (3, 4, 5)]
    assert calls == [f for f in faces for _ in range(2)]  # each year: its surface, its old corners


def test_vertex_neighbours_are_trimeshs_listed_in_ascending_order(cylinder):
    """The neighbours were listed in the order of a Python set per vertex (trimesh's, built in
    a Python loop: 45 ms on 41k vertices), an order nothing chose, though it decides a walk's
    ties and which vertex gets which draw of the random pattern. Now they are trimesh's
    neighbours in ascending order, as CSR arrays from one sort of the edges."""
    from woodcam.woodify.cracks import _neighbours

    mesh = cylinder.surface(3.0)
    expect = trimesh.Trimesh(mesh.vertices, mesh.faces, process=False).vertex_neighbors
    ptr, idx = _neighbours(mesh)
    assert ptr.dtype == idx.dtype == np.int64 and len(ptr) == len(mesh.vertices) + 1 and ptr[-1] == len(idx)
    assert [idx[a:b].tolist() for a, b in zip(ptr[:-1], ptr[1:])] == [sorted(int(i) for i in nb) for nb in expect]


def test_a_walk_tie_goes_to_the_lowest_vertex_and_a_relief_ring_is_ascending():
    """Ties were broken by the neighbour sets' order: now explicitly by the lowest index. On a
    flat grid walked along (1, 1), a vertex's +x (v + 1) and +y (v + g) neighbours tie exactly:
    the walk takes +x. A crack's relief ring (its path and neighbours, grown a few times) is
    the set-based ring, as sorted unique indices (the random pattern draws in its order)."""
    from woodcam.woodify.cracks import _grow_ring, _neighbours, _walk

    g = 6
    j, i = np.divmod(np.arange((g - 1) ** 2), g - 1)
    a = j * g + i
    grid = trimesh.Trimesh(np.stack([*np.divmod(np.arange(g * g), g)[::-1], np.zeros(g * g)], 1),
                           np.concatenate([np.stack([a, a + g, a + 1], 1), np.stack([a + 1, a + g, a + g + 1], 1)]),
                           process=False)
    # the diagonal split runs (v + 1, v + g): with the quads split so, (1, 1) ties +x and +y
    nb = _neighbours(grid)
    d = np.array([1.0, 1.0, 0.0]) / np.sqrt(2.0)
    assert _walk(np.asarray(grid.vertices, float), nb, 2, d, 1.0, set())[:2] == [2, 3]  # not 2 + g
    lists = [set(nb[1][x:y].tolist()) for x, y in zip(nb[0][:-1], nb[0][1:])]
    for path, steps in (([14, 8, 9], 1), ([0], 2), ([35, 35, 7], 3)):
        ring = set(path)
        for _ in range(steps):
            ring |= {b for v in list(ring) for b in lists[v]}
        got = _grow_ring(np.array(path), nb, steps)
        assert got.tolist() == sorted(ring), (path, steps)


def test_cracks_of_a_growing_cylinder_run_along_its_axis(cylinder):
    cs = simulate_cracks(cylinder, [1, 2, 3, 4, 5])
    lat = np.abs(cs.crack_points[:, 2]) < 22
    assert lat.sum() >= 10
    assert np.mean(np.abs(cs.crack_directions[lat, 2])) > 0.95
    e = _edge_dirs(cs)
    assert len(e) > 20 and np.mean(np.abs(e[:, 2])) > 0.9
    # cracks carried year to year: the last year's mesh still has cracks inserted earlier
    assert cs.log[0]["cracks"] > 0 and len(cs.crack_edges) > cs.log[-1]["cracks"]


def test_crack_patterns_steer_the_direction(cylinder):
    horiz = _edge_dirs(simulate_cracks(cylinder, [3, 4, 5], pattern="horizontal"))
    assert len(horiz) > 20 and np.mean(np.abs(horiz[:, 2])) < 0.1
    rand = _edge_dirs(simulate_cracks(cylinder, [3, 4, 5], pattern="random", seed=1))
    assert 0.2 < np.mean(np.abs(rand[:, 2])) < 0.8
    region = simulate_cracks(cylinder, [3, 4, 5], region=(8.0, 0.0, 10.0, 6.0))
    pts = region.crack_points
    assert len(pts) > 0 and np.all(np.linalg.norm(pts - [8 + cylinder.tau(5.0), 0, 10], axis=1) < 6 + 4 * cylinder.front.grid.spacing_mm + 3)


def test_relief_zero_opens_fewer_cracks_than_one(cylinder):
    few = simulate_cracks(cylinder, [3, 4, 5], relief=0.0)
    many = simulate_cracks(cylinder, [3, 4, 5], relief=1.0)
    assert sum(x["cracks"] for x in few.log) < sum(x["cracks"] for x in many.log)
    with pytest.raises(WoodcamError, match="relief must lie in"):
        simulate_cracks(cylinder, [3, 4], relief=1.5)


def test_texture_coordinates_stay_put_while_growing():
    """A vertex attribute (here the input's own coordinates) carried to the grown surface is
    the point the growth came from: for a sphere, the radial projection."""
    m = trimesh.creation.icosphere(subdivisions=4, radius=10.0)
    r = woodify(m, 10, growth_mm=10.0, resolution=56)
    s = r.surface(10.0)
    origins, tri = r.origins(s.vertices)
    _, bary = barycentric_on(m, origins, tri)
    carried = carry(m, m.vertices, tri, bary)
    radial = 10.0 * s.vertices / np.linalg.norm(s.vertices, axis=1, keepdims=True)
    h = r.front.grid.spacing_mm
    assert np.percentile(np.linalg.norm(carried - radial, axis=1), 95) < 0.5 * h
    # eccentric: the characteristic is no longer radial, but origins still lie on the input
    r2 = woodify(m, 10, growth_mm=10.0, resolution=56, eccentricity=0.3)
    o2, _ = r2.origins(r2.surface(10.0).vertices)
    assert np.abs(np.linalg.norm(o2, axis=1) - 10.0).max() < 0.5 * h


def test_brush_gain_speeds_growth_where_painted():
    m = trimesh.creation.icosphere(subdivisions=4, radius=10.0)
    brush = Brush(centre_mm=(10.0, 0.0, 0.0), radius_mm=3.0, gain=1.8)
    r = woodify(m, 10, growth_mm=8.0, resolution=56, brushes=[brush])
    f = r.field
    tau = r.tau(10.0)
    # under the brush centre the front moved 1.8x as far (gain is 1.8 there), far from it 1x
    h = r.front.grid.spacing_mm
    assert f.arrival(np.array([[10.0 + 1.8 * tau, 0, 0]]))[0] == pytest.approx(tau, abs=1.5 * h)
    assert f.arrival(np.array([[-10.0 - tau, 0, 0]]))[0] == pytest.approx(tau, abs=0.5 * h)
    # a direction brush bends the growth: strength towards +Z on the +X side
    bend = Brush(centre_mm=(10.0, 0.0, 0.0), radius_mm=3.0, direction=(0, 0, 1), strength=0.5)
    r2 = woodify(m, 10, growth_mm=8.0, resolution=56, brushes=[bend])
    assert r2.front.method == "anisotropic"
    top = r2.field.arrival(np.array([[17.0, 0, 4.0]]))[0]
    bottom = r2.field.arrival(np.array([[17.0, 0, -4.0]]))[0]
    assert top < bottom - 0.5 * h
    # and it bends only where painted: on the -X side the growth stays symmetric
    left = r2.field.arrival(np.array([[-17.0, 0, 4.0], [-17.0, 0, -4.0]]))
    assert abs(left[0] - left[1]) < 0.25 * h
    with pytest.raises(WoodcamError, match="brush gain must be > 0"):
        Brush(centre_mm=(0, 0, 0), radius_mm=1.0, gain=0.0)


def test_vertex_attribute_gain_is_painted_like_a_brush():
    m = trimesh.creation.icosphere(subdivisions=4, radius=10.0)
    gain = np.where(m.vertices[:, 2] > 0, 1.5, 1.0)  # the upper half grows 1.5x as fast
    r = woodify(m, 10, growth_mm=8.0, resolution=56, vertex_gain=gain)
    h = r.front.grid.spacing_mm
    tau = r.tau(10.0)
    assert r.field.arrival(np.array([[0, 0, 10.0 + 1.5 * tau]]))[0] == pytest.approx(tau, abs=h)
    assert r.field.arrival(np.array([[0, 0, -10.0 - tau]]))[0] == pytest.approx(tau, abs=0.5 * h)


def test_groove_cuts_cracks_into_the_surface(cylinder):
    from woodcam.woodify.bark import groove

    cs = simulate_cracks(cylinder, [3, 4, 5])
    width = np.zeros(len(cs.mesh.vertices))
    width[cs.crack_edges.ravel()] = 1.0
    cut = groove(cs.mesh, width, 0.5)
    r0 = np.hypot(*cs.mesh.vertices[:, :2].T)
    r1 = np.hypot(*cut.vertices[:, :2].T)
    lat = np.abs(cs.mesh.vertices[:, 2]) < 20
    on = lat & (width > 0)
    assert np.all(r1[on] < r0[on] - 0.4) and np.allclose(r1[lat & (width == 0)], r0[lat & (width == 0)])


def test_brush_file_round_trip_and_errors(tmp_path):
    from woodcam.woodify import load_brushes

    p = tmp_path / "brushes.json"
    p.write_text('{"brushes": [{"centre_mm": [1, 2, 3], "radius_mm": 4, "gain": 1.5, '
                 '"direction": [0, 0, 2], "strength": 0.25}, {"centre_mm": [0, 0, 0], "radius_mm": 1}]}')
    a, b = load_brushes(p)
    assert a == Brush((1, 2, 3), 4.0, 1.5, (0.0, 0.0, 1.0), 0.25) and b.gain == 1.0
    assert a.weight(np.array([[1.0, 2.0, 3.0], [5.0, 2.0, 3.0]])) == pytest.approx([1.0, np.exp(-0.5)])
    p.write_text('{"brushes": [{"radius_mm": 4}]}')
    with pytest.raises(WoodcamError, match="brushes file .*: brush 0 .* must be like .*: missing 'centre_mm'"):
        load_brushes(p)


def test_a_brush_file_with_a_misspelt_key_is_refused_naming_it(tmp_path):
    """load_brushes dropped keys it did not know: 'stregth': 0.3 painted a brush of strength 0
    and a file's 'brushes' beside a 'brushez' list lost the second without a word. Now the key
    is named with the nearest known one and all of them."""
    from woodcam.woodify import load_brushes

    p = tmp_path / "brushes.json"
    for text, said in (('[{"centre_mm": [1, 2, 3], "radius_mm": 4, "stregth": 0.3}]',
                        r"brush 0 has an unknown key 'stregth'; did you mean 'strength'\? the keys are "
                        r"centre_mm, direction, gain, radius_mm, strength; write it like"),
                       ('[{"centre_mm": [1, 2, 3], "radius_mm": 4}, {"centre_mm": [0, 0, 0], "radius": 4, "colour": 1}]',
                        r"brush 1 has an unknown key 'radius' \(of 2\); did you mean 'radius_mm'\?"),
                       ('[{"centre_mm": [1, 2, 3], "radius_mm": 4, "zzz": 1}]',
                        r"brush 0 has an unknown key 'zzz'; the keys are centre_mm,"),
                       ('{"brushes": [], "brushez": [{"centre_mm": [1, 2, 3], "radius_mm": 4}]}',
                        r"brushes file '.*' has an unknown key 'brushez'; did you mean 'brushes'\? the keys are brushes;")):
        p.write_text(text)
        with pytest.raises(WoodcamError, match=said):
            load_brushes(p)
    p.write_text('{"brushes": [{"centre_mm": [1, 2, 3], "radius_mm": 4, "strength": 0.3}]}')
    assert load_brushes(p) == [Brush((1, 2, 3), 4.0, strength=0.3)]


def test_a_brush_file_is_read_as_every_json_file_is(tmp_path):
    """load_brushes read its JSON with json.loads of read_text, not the project's reader: a file
    nested too deep was a bare RecursionError, a missing file read "must be JSON like ...: [Errno
    2]", and float() took "radius_mm": "4" and "gain": true as 4.0 and 1.0. Now read_json_file
    (the file named, NaN refused), and the numbers as Brush checks them."""
    from woodcam.woodify import load_brushes

    p = tmp_path / "brushes.json"
    for text, said in (("[" * 100000 + "]" * 100000, "brushes file '.*' must be valid JSON with finite numbers; maximum recursion"),
                       ('[{"centre_mm": [1, 2, 3], "radius_mm": NaN}]', "must be valid JSON with finite numbers; non-finite number NaN"),
                       ('[{"centre_mm": [1, 2, 3], "radius_mm": "4"}]', "brush 0 .*: brush radius_mm must be a number; got '4'"),
                       ('[{"centre_mm": [1, 2, 3], "radius_mm": 4, "gain": true}]', "brush 0 .*: brush gain must be a number; got True"),
                       ('{"brush": []}', "must hold a list of brushes .*; got no 'brushes'; write it like"),
                       ('[{"centre_mm": [1, 2, 3], "radius_mm": 4}, 5]', "brush 1 must be a JSON object; got 5")):
        p.write_text(text)
        with pytest.raises(WoodcamError, match=said):
            load_brushes(p)
    with pytest.raises(WoodcamError, match=r"brushes file: cannot read '.*none.json' \(No such file"):
        load_brushes(tmp_path / "none.json")
    with pytest.raises(WoodcamError, match="load_brushes: path must be a file path .*got None"):
        load_brushes(None)
    p.write_text('[{"centre_mm": [1, 2, 3], "radius_mm": 4}]')
    assert load_brushes(str(p)) == [Brush((1, 2, 3), 4.0)]


def test_corner_uv_gives_each_face_the_corners_textured_mesh_gives_it():
    """A face across the wrap (u near 0 and 1) has u + 1 on its low corners, the others keep
    their vertices' coordinates: the same corners as textured_mesh's split copies."""
    from woodcam.woodify.bark import corner_uv, textured_mesh

    mesh = trimesh.Trimesh([[0, 0, 0], [1, 0, 0], [0, 1, 0], [1, 1, 0], [2, 0, 0]],
                           [[0, 1, 2], [1, 3, 2], [1, 4, 3]], process=False)
    uv = np.array([[0.95, 0.1], [0.05, 0.1], [0.9, 0.6], [0.1, 0.6], [0.2, 0.1]])
    c = corner_uv(uv, mesh.faces)
    assert c.shape == (3, 3, 2)
    assert np.allclose(c[0, :, 0], [0.95, 1.05, 0.9]) and np.allclose(c[1, :, 0], [1.05, 1.1, 0.9])
    assert np.allclose(c[2], uv[mesh.faces[2]])          # not across the wrap: as given
    t = textured_mesh(mesh, uv, np.zeros((4, 4, 3), np.uint8))
    assert np.allclose(np.asarray(t.visual.uv)[t.faces], c)


def test_paint_crack_faces_draws_an_edge_in_every_face_that_holds_it():
    """Edge (0, 1) lies in two faces laid in different places of the atlas (a chart seam): the
    crack is drawn in both, dark along the edge; texels away from it are untouched; no edges,
    an untouched copy."""
    from woodcam.woodify.bark import paint_crack_faces

    img = np.full((40, 40, 3), 200, np.uint8)
    faces = np.array([[0, 1, 2], [1, 0, 3]])
    corner_xy = np.array([[[5, 5], [15, 5], [10, 12]],      # face 0: edge 0-1 along row 5
                          [[30, 35], [20, 35], [25, 28]]],  # face 1 elsewhere: edge 1-0 along row 35
                         float)
    assert np.array_equal(paint_crack_faces(img, corner_xy, faces, np.zeros((0, 2), int), 1), img)
    out = paint_crack_faces(img, corner_xy, faces, np.array([[1, 0]]), 1)
    assert out is not img and (img == 200).all()             # a copy
    assert out[4:6, 7:13].max() < 120 and out[34:36, 22:28].max() < 120
    changed = (out != 200).any(2)
    changed[2:8, 3:18] = changed[32:38, 18:33] = False
    assert not changed.any()                                  # edges 1-2, 2-0 are not cracks


def test_separation_local_takes_a_trimesh_only(cylinder):
    """The public separation_local took a trimesh or the module's private _MeshArrays (whatever
    had vertex_faces, faces, tri...): its input was a private type. Now a trimesh, checked at
    the door; the crack loop's read-once arrays go through the private _separation_round."""
    from woodcam.woodify.cracks import _MeshArrays

    mesh = cylinder.surface(4.0)
    old, _ = trace_back(cylinder.front, mesh.vertices, until_mm=cylinder.tau(3.0))
    sig = growth_stress(mesh, old)
    ring = np.array([5, 17, 400])
    with pytest.raises(WoodcamError, match=r"separation_local: mesh must be a trimesh.Trimesh; got _MeshArrays"):
        separation_local(_MeshArrays.of(mesh), sig, ring)
    with pytest.raises(WoodcamError, match=r"stress must be \(f, 3, 3\)"):
        separation_local(mesh, sig[:-1], ring)
    with pytest.raises(WoodcamError, match=r"vertices must be a 1-D integer array .* values 5..\d+"):
        separation_local(mesh, sig, np.array([5, len(mesh.vertices)]))


def test_picture_density_is_the_densest_parts_not_the_mean():
    """The texels per mm an input's picture is moved into an atlas at (cracks drawn into it) was
    an area mean, so wherever the input's UVs are denser than the mean the picture was resampled
    coarser ('no coarser than it was', README). Half a surface at 10 texels/mm and half at 2
    ask 10 (the mean said sqrt((100 + 4) / 2) = 7.2); a sliver face does not set it."""
    from woodcam.woodify.bark import picture_density

    # two 10 x 10 mm squares side by side, two triangles each; a 100 x 100 px picture
    v = np.array([[0, 0, 0], [10, 0, 0], [10, 10, 0], [0, 10, 0], [20, 0, 0], [20, 10, 0]], float)
    f = np.array([[0, 1, 2], [0, 2, 3], [1, 4, 5], [1, 5, 2]])
    mesh = trimesh.Trimesh(v, f, process=False)
    image = np.zeros((100, 100, 3), np.uint8)
    fine = np.array([[0, 0], [1, 0], [1, 1], [0, 1]], float)         # 100 px over 10 mm: 10 /mm
    coarse = fine * 0.2                                                 # 20 px over 10 mm: 2 /mm
    corners = np.stack([fine[[0, 1, 2]], fine[[0, 2, 3]], coarse[[0, 1, 3]], coarse[[0, 3, 2]]])
    assert picture_density(mesh, corners, image) == pytest.approx(10.0)
    # a sliver (next to no area, a whole picture on it) is under the 5 % left out
    sliver = trimesh.Trimesh(np.vstack([v, [[0, 0, 0], [10, 0, 0], [5, 1e-4, 0]]]),
                             np.vstack([f, [[6, 7, 8]]]), process=False)
    assert picture_density(sliver, np.concatenate([corners, fine[None, [0, 1, 2]]]), image) == pytest.approx(10.0)


@pytest.mark.parametrize("kwargs, message", [
    ({"period_mm": 0.0}, r"SolidBark: period_mm must be a finite number > 0; got 0.0"),
    ({"period_mm": float("nan")}, r"SolidBark: period_mm must be a finite number > 0"),
    ({"axis": (0.0, 0.0, 0.0)}, r"SolidBark: axis must be a non-zero direction"),
    ({"axis": (0.0, 1.0)}, r"SolidBark: axis must be three finite numbers"),
    ({"centre_mm": (0.0, float("inf"), 0.0)}, r"SolidBark: centre_mm must be three finite numbers"),
    ({"seed": 1.5}, r"SolidBark: seed must be an integer"),
])
def test_solid_bark_refuses_what_would_colour_nan(kwargs, message):
    """SolidBark checked nothing: a period of 0 coloured every point NaN, a zero axis gave a
    NaN frame. Each is refused naming the argument, the rule and the value."""
    from woodcam.woodify.bark import SolidBark

    good = {"axis": (0.0, 0.0, 2.0), "centre_mm": (1.0, 2.0, 3.0), "period_mm": 50.0, "seed": 0}
    rgb = SolidBark(**good).color(np.random.default_rng(0).uniform(-40, 40, (200, 3)))
    assert np.isfinite(rgb).all() and rgb.min() >= 0 and rgb.max() <= 1
    with pytest.raises(WoodcamError, match=message):
        SolidBark(**{**good, **kwargs})


@pytest.mark.parametrize("seed", [-1, 2**32])
def test_a_bark_seed_out_of_numpy_range_is_named(seed):
    """Review h15 item 10: SolidBark(seed=-1) was numpy's bare ValueError of default_rng."""
    from woodcam.woodify.bark import SolidBark

    with pytest.raises(WoodcamError, match=rf"SolidBark: seed must be an integer in \[0, .*got {seed}"):
        SolidBark((0, 0, 1), (0, 0, 0), 100.0, seed=seed)


def _walk_loop(verts, neighbours, start, direction, length_mm, cracked_edges):
    """The crack walk as the per-step numpy loop it was (the reference of the compiled one)."""
    path, v, travelled, d = [start], start, 0.0, direction
    while travelled < length_mm:
        nb = neighbours[v]
        if not nb:
            break
        vec = verts[nb] - verts[v]
        ln = np.linalg.norm(vec, axis=1)
        cos = (vec @ d) / np.maximum(ln, 1e-12)
        k = int(np.argmax(cos))
        if cos[k] < 0.6:
            break
        nxt = nb[k]
        cracked_edges.add((min(v, nxt), max(v, nxt)))
        travelled += ln[k]
        d = vec[k] / ln[k] * 0.3 + d * 0.7
        d /= np.linalg.norm(d)
        v = nxt
        path.append(v)
    return path


def test_the_compiled_crack_walk_takes_the_loops_paths():
    """Refactor check: the compiled walk (cracks._walk) takes the very vertices and edges the
    per-step numpy loop took, on 3000 walks each over a noisy icosphere (13.5k steps), a
    cylinder and a flat grid whose first steps tie between two neighbours."""
    from woodcam.woodify.cracks import _neighbours, _walk

    rng = np.random.default_rng(0)
    # a flat grid whose quads are split along (-1, 1): walked along (1, 1), a vertex's +x and +y
    # neighbours tie exactly (the first listed wins, as argmax)
    g = 30
    j, i = np.divmod(np.arange((g - 1) ** 2), g - 1)
    a = j * g + i
    a = a[(i < g - 1) & (j < g - 1)]
    grid = trimesh.Trimesh(np.stack([*np.divmod(np.arange(g * g), g)[::-1], np.zeros(g * g)], 1),
                           np.concatenate([np.stack([a, a + 1, a + g], 1), np.stack([a + 1, a + g + 1, a + g], 1)]),
                           process=False)
    for mesh, noise in ((trimesh.creation.icosphere(subdivisions=5, radius=20.0), 0.05),
                        (trimesh.creation.cylinder(radius=8.0, height=60.0, sections=64), 0.0),
                        (grid, 0.0)):
        V = np.asarray(mesh.vertices).view(np.ndarray) + rng.normal(0, noise, mesh.vertices.shape)
        csr = _neighbours(mesh)
        nb = [csr[1][a:b].tolist() for a, b in zip(csr[0][:-1], csr[0][1:])]
        n = 3000
        starts = rng.integers(0, len(V), n)
        dirs = rng.standard_normal((n, 3))
        dirs[: n // 3] = [1.0, 1.0, 0.0] if mesh is grid else [0.0, 0.0, 1.0]  # ties, the axis
        dirs /= np.linalg.norm(dirs, axis=1, keepdims=True)
        lens = rng.uniform(0.3, 6.0, n)
        old, new = set(), set()
        for s, d, ln in zip(starts, dirs, lens):
            want = _walk_loop(V, nb, int(s), d, ln, old)
            got = _walk(V, csr, int(s), d, ln, new)
            assert got == want, (int(s), d, ln)
        assert new == old and len(new) > 300
