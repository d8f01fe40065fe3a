"""The generic neural growth field (seed 000 §3.2.1-3.2.2, §3.2.5): data, model, training."""

from __future__ import annotations

import csv
import json

import numpy as np
import pytest

torch = pytest.importorskip("torch")

from woodcam.errors import WoodcamError  # noqa: E402
from woodcam.fields.base import LogFrame  # noqa: E402
from woodcam.fields.radial import laplacian_smoother  # noqa: E402
from woodcam.fields.neural import (  # noqa: E402
    LOG_NAME, MODELS_DIR, SPEC_NAME, WEIGHTS_NAME, GTFSpec, build_model,
    encode, family_gtf, load_model, make_training_set, random_radius_samples, train_gtf,
)
from woodcam.fields.radial import RadialScalingField, RadiusFunction  # noqa: E402

TINY = dict(n_fields=8, points_per_field=64, latent_dim=4, hidden=16, layers=2, n_harmonics=3,
            batch_fields=4, batch_points=16, steps=40, checkpoint_every=20, log_every=10)


def test_family_matches_radial_field():
    """The vectorised eq. 7-9 equals RadialScalingField with ring width 1 and half length 1."""
    rng = np.random.default_rng(3)
    rm, rp = random_radius_samples(rng, 1), random_radius_samples(rng, 1)
    f = RadialScalingField(LogFrame((0, 0, 0), (0, 0, 1), reference=(1, 0, 0)), 1.0,
                           RadiusFunction(rm[0]), RadiusFunction(rp[0]), 1.0)
    p = np.random.default_rng(1).uniform(-1.2, 1.2, (500, 3))
    np.testing.assert_allclose(family_gtf(p[None], rm, rp)[0], f(p), rtol=1e-12, atol=1e-12)


def test_smoother_matches_from_constraints():
    c = np.clip(np.random.default_rng(5).normal(1, 0.1, 15), 0.5, 1.5)
    np.testing.assert_allclose(c @ laplacian_smoother(15, 360).T,
                               RadiusFunction.from_constraints(c).samples, atol=1e-10)


def test_training_set_pith_fraction_and_values():
    spec = GTFSpec(**{**TINY, "points_per_field": 100})
    pts, vals = make_training_set(spec)
    assert pts.shape == (8, 100, 3) and vals.shape == (8, 100) and pts.dtype == np.float32
    near = np.all(np.abs(pts[..., :2]) <= 0.1, axis=-1)
    assert near[:, :20].all()  # the first 20 % are drawn near the pith
    assert np.abs(pts).max() <= 1.0
    rho = np.hypot(pts[..., 0], pts[..., 1])
    # r' in [0.5, 1.5] bounds the growth time between rho / 1.5 and rho / 0.5
    assert np.all(vals >= rho / 1.5 - 1e-6) and np.all(vals <= rho / 0.5 + 1e-6)


def test_encoding_is_cylindrical_and_continuous():
    phi = np.linspace(-np.pi, np.pi, 37)
    r, z = 0.7, -0.3
    p = torch.tensor(np.stack([r * np.cos(phi), r * np.sin(phi), np.full_like(phi, z)], -1))
    e = encode(p, 4).numpy()
    assert e.shape == (37, 10)
    np.testing.assert_allclose(e[:, 0], r, atol=1e-12)
    np.testing.assert_allclose(e[:, 1], z, atol=1e-12)
    for k in range(1, 5):
        np.testing.assert_allclose(e[:, 2 * k], np.cos(k * phi), atol=1e-9)
        np.testing.assert_allclose(e[:, 2 * k + 1], np.sin(k * phi), atol=1e-9)
    # no jump across the negative x axis (where atan2 and eq. 4's arccos/arcsin fold)
    a = encode(torch.tensor([[-0.5, 1e-9, 0.0], [-0.5, -1e-9, 0.0]], dtype=torch.float64), 4)
    assert float((a[0] - a[1]).abs().max()) < 1e-6
    # finite at the pith
    assert torch.isfinite(encode(torch.zeros(1, 3, dtype=torch.float64), 4)).all()


def test_model_shape_grad_and_initial_field():
    spec = GTFSpec(**TINY)
    net = build_model(spec)
    codes = torch.randn(5, 1, 4, requires_grad=True)
    p = torch.rand(5, 7, 3) * 2 - 1
    out = net(codes, p)
    assert out.shape == (5, 7)
    # zero-initialised last layer: the untrained model is the mean field f = rho
    torch.testing.assert_close(out, torch.sqrt(p[..., 0] ** 2 + p[..., 1] ** 2 + 1e-12))
    (out.sum() + sum(q.sum() for q in net.parameters())).backward()
    assert codes.grad is not None and codes.grad.shape == codes.shape
    # one code broadcast over many points
    assert net(torch.zeros(4), p.reshape(-1, 3)).shape == (35,)


def test_spec_round_trip_and_errors(tmp_path):
    spec = GTFSpec(**TINY)
    assert GTFSpec.load(spec.save(tmp_path / "s.json")) == spec
    with pytest.raises(WoodcamError, match="unknown keys"):
        GTFSpec.from_dict({**TINY, "depth": 3})
    with pytest.raises(WoodcamError, match="spec.hidden must be an integer >= 1"):
        GTFSpec(**{**TINY, "hidden": 0})
    with pytest.raises(WoodcamError, match="pith_fraction"):
        GTFSpec(**{**TINY, "pith_fraction": 1.5})
    (tmp_path / "bad.json").write_text("[1, 2]")
    with pytest.raises(WoodcamError, match="JSON object"):
        GTFSpec.load(tmp_path / "bad.json")


@pytest.mark.parametrize("key, value, rule", [
    ("seed", -1, "spec.seed must be an integer >= 0; got -1"),
    ("seed", "a", "spec.seed must be an integer >= 0; got 'a'"),
    ("n_fields", 4.5, "spec.n_fields must be an integer >= 1; got 4.5"),
    ("latent_dim", True, "spec.latent_dim must be an integer >= 1; got True"),
    ("lr_net", True, "spec.lr_net must be a positive number; got True"),
    ("lr_floor", 5, "spec.lr_floor must be in (0, 1]"),
    ("radius_samples", 1, "spec.n_constraints must be at most spec.radius_samples (1"),
    # sigma 50 was taken: every constraint clipped to 0.5 or 1.5, not N(1, sigma)
    ("constraint_sigma", 50, "spec.constraint_sigma must be a finite number in (0, 0.5]; got 50"),
    ("pith_fraction", -0.1, "spec.pith_fraction must be a finite number in [0, 1]; got -0.1"),
])
def test_spec_file_with_a_bad_value_is_refused_naming_the_file(tmp_path, key, value, rule):
    """A seed of -1 or 4.5 fields in a spec file passed the door and failed in numpy's words
    ('expected non-negative integer', "'float' object cannot be interpreted as an integer")
    after the spec had been written into OUT."""
    path = tmp_path / "spec.json"
    path.write_text(json.dumps({**TINY, key: value}))
    with pytest.raises(WoodcamError) as e:
        GTFSpec.load(path)
    assert str(path) in str(e.value) and rule in str(e.value), e.value


def test_spec_takes_the_ends_of_the_documented_ranges():
    """pith_fraction 0 (no points near the pith) was refused as 'must be a positive number'
    although its documented range is [0, 1]."""
    for key, value in (("pith_fraction", 0), ("pith_fraction", 1), ("constraint_sigma", 0.5)):
        assert getattr(GTFSpec(**{**TINY, key: value}), key) == value


def test_training_refuses_more_batch_fields_than_fields_before_writing(tmp_path):
    spec = GTFSpec(**{**TINY, "batch_fields": 9})      # 8 fields: numpy's "larger sample than population"
    with pytest.raises(WoodcamError, match=r"spec.batch_fields must be at most spec.n_fields \(8\)"):
        train_gtf(spec, tmp_path, progress=False)
    assert not (tmp_path / SPEC_NAME).exists()


def test_resumed_training_equals_straight_run(tmp_path):
    spec = GTFSpec(**TINY)
    straight = train_gtf(spec, tmp_path / "a", progress=False)
    train_gtf(spec, tmp_path / "b", steps=20, progress=False)
    resumed = train_gtf(spec, tmp_path / "b", progress=False)
    sa = torch.load(tmp_path / "a" / WEIGHTS_NAME, weights_only=True)
    sb = torch.load(tmp_path / "b" / WEIGHTS_NAME, weights_only=True)
    for k in sa:
        torch.testing.assert_close(sa[k], sb[k], rtol=1e-5, atol=1e-6)
    np.testing.assert_allclose(straight["codes"], resumed["codes"], rtol=1e-5, atol=1e-6)
    np.testing.assert_array_equal(straight["step"], resumed["step"])
    np.testing.assert_allclose(straight["loss"], resumed["loss"], rtol=1e-5)
    # spec, weights and log written; the log holds every logged step
    assert GTFSpec.load(tmp_path / "b" / SPEC_NAME) == spec
    with open(tmp_path / "b" / LOG_NAME, newline="") as fh:
        rows = list(csv.DictReader(fh))
    assert [int(r["step"]) for r in rows] == [10, 20, 30, 40]
    # a checkpoint of another spec is refused
    with pytest.raises(WoodcamError, match="another spec"):
        train_gtf(GTFSpec(**{**TINY, "seed": 1}), tmp_path / "b", progress=False)
    # and leaves the folder as it was: the spec beside the weights is still theirs
    assert GTFSpec.load(tmp_path / "b" / SPEC_NAME) == spec


def test_a_failed_run_leaves_the_spec_beside_the_weights_that_it_made(tmp_path):
    """The spec was written when a run started: one that then failed (or was killed) left the
    new spec beside the previous run's gtf.pt, which loaded under it without a word when only
    the seed or a rate had changed."""
    spec = GTFSpec(**TINY)
    train_gtf(spec, tmp_path, progress=False)

    def fails():
        raise RuntimeError("killed while making the training set")

    with pytest.raises(RuntimeError, match="killed"):
        train_gtf(GTFSpec(**{**TINY, "seed": 1}), tmp_path, resume=False, progress=False, training_set=fails)
    assert GTFSpec.load(tmp_path / SPEC_NAME) == spec
    assert load_model(tmp_path)[1] == spec


def test_training_reduces_the_error(tmp_path):
    spec = GTFSpec(**{**TINY, "steps": 300, "hidden": 32, "checkpoint_every": 300, "log_every": 50,
                      "lr_net": 3e-3, "lr_latent": 3e-2})
    pts, vals = make_training_set(spec)
    untrained_l1 = np.abs(np.hypot(pts[..., 0], pts[..., 1]) - vals).mean()  # f = rho at init
    r = train_gtf(spec, tmp_path, progress=False)
    assert r["final_l1"] < 0.75 * untrained_l1


def test_packaged_model():
    """The committed weights load, match their spec, and were trained to a small error."""
    # committed with the package (pyproject package-data "models/*"): a missing file is a
    # packaging fault, not a model still to be trained (this skipped, and passed, without it)
    assert (MODELS_DIR / WEIGHTS_NAME).is_file() and (MODELS_DIR / SPEC_NAME).is_file(), MODELS_DIR
    net, spec = load_model()
    assert sum(p.numel() for p in net.parameters()) < 500_000
    assert (MODELS_DIR / WEIGHTS_NAME).stat().st_size < 2_000_000
    summary = json.loads((MODELS_DIR / "gtf_train_summary.json").read_text())
    assert summary["steps"] == spec.steps
    # The figure itself, recomputed rather than read: on fields the model never saw (another
    # seed), a latent code fitted with the weights frozen reproduces the field to ~0.1 % of the
    # domain radius (measured 0.0008-0.0012; the training log says 0.0010).
    from dataclasses import replace

    threads = torch.get_num_threads()
    torch.set_num_threads(1)  # tiny batches: threads only contend on a shared machine
    pts, vals = make_training_set(replace(spec, seed=99, n_fields=4, points_per_field=300))
    P, V = torch.tensor(pts), torch.tensor(vals)
    for w in net.parameters():
        w.requires_grad_(False)
    codes = torch.zeros(4, 1, spec.latent_dim, requires_grad=True)
    opt = torch.optim.Adam([codes], lr=0.05)
    try:
        for _ in range(120):
            opt.zero_grad()
            (net(codes, P) - V).abs().mean().backward()
            opt.step()
        with torch.no_grad():
            fitted = (net(codes, P) - V).abs().mean(dim=1).numpy()
            mean_field = (net(torch.zeros_like(codes), P) - V).abs().mean(dim=1).numpy()
    finally:
        torch.set_num_threads(threads)
    assert np.all(fitted < 0.005), fitted          # normalised units
    assert np.all(fitted < 0.1 * mean_field), (fitted, mean_field)
    # c = 0 decodes a plausible member of the family: 0 on the pith, ~rho elsewhere
    p = torch.tensor([[0.0, 0.0, 0.0], [0.5, 0.0, 0.0], [0.0, -0.8, 0.5]])
    out = net(torch.zeros(spec.latent_dim), p).numpy()
    np.testing.assert_allclose(out, [0.0, 0.5, 0.8], atol=0.1)


def test_load_model_missing(tmp_path):
    with pytest.raises(WoodcamError, match="needs gtf_spec.json and gtf.pt"):
        load_model(tmp_path)


@pytest.mark.parametrize("damage", ["truncated", "empty", "another net"])
def test_load_model_refuses_broken_weights_in_one_line_naming_the_file(tmp_path, damage):
    """A cut, empty or foreign gtf.pt was torch's bare EOFError, 'OSError: [Errno 22] Invalid
    argument' or a many-line RuntimeError listing every tensor."""
    spec = GTFSpec(**TINY)
    spec.save(tmp_path / SPEC_NAME)
    torch.save(build_model(spec).state_dict(), tmp_path / WEIGHTS_NAME)
    load_model(tmp_path)                                   # the intact folder loads
    w = tmp_path / WEIGHTS_NAME
    if damage == "truncated":
        w.write_bytes(w.read_bytes()[: w.stat().st_size // 2])
    elif damage == "empty":
        w.write_bytes(b"")
    else:
        torch.save(build_model(GTFSpec(**{**TINY, "hidden": 8})).state_dict(), w)
    with pytest.raises(WoodcamError) as e:
        load_model(tmp_path)
    msg = str(e.value)
    assert "\n" not in msg and str(w) in msg and "woodcam train gtf" in msg, msg
    assert {"truncated": "cut short", "empty": "empty", "another net": "another net"}[damage] in msg, msg


@pytest.mark.parametrize("damage", ["truncated", "empty"])
def test_a_cut_or_empty_checkpoint_is_named_as_such(tmp_path, damage):
    """A cut checkpoint was 'is not a woodcam training checkpoint of tensors and plain data
    (OSError); it was refused, nothing in it was run', an empty one the same with EOFError:
    words for a crafted file, not for a damaged one."""
    spec = GTFSpec(**TINY)
    train_gtf(spec, tmp_path, steps=20, progress=False)
    ckpt = tmp_path / "gtf_checkpoint.pt"
    ckpt.write_bytes(b"" if damage == "empty" else ckpt.read_bytes()[: ckpt.stat().st_size // 2])
    with pytest.raises(WoodcamError) as e:
        train_gtf(spec, tmp_path, progress=False)
    want = "is empty" if damage == "empty" else "is cut short or another kind of file"
    assert f"checkpoint {ckpt} {want}" in str(e.value) and "--no-resume" in str(e.value), e.value


def test_fewer_steps_than_the_checkpoint_says_so(tmp_path):
    """steps=20 over a 40-step checkpoint wrote the 40-step weights without a word (the CLI
    printed "trained 40 steps" for '--steps 20')."""
    from woodcam.errors import WoodcamWarning

    spec = GTFSpec(**TINY)
    train_gtf(spec, tmp_path, progress=False)
    with pytest.warns(WoodcamWarning, match=r"at step 40, past steps=20: nothing is trained.*--no-resume"):
        r = train_gtf(spec, tmp_path, steps=20, progress=False)
    assert int(r["step"][-1]) == 40


def test_a_training_set_past_the_memory_limit_is_refused_before_any_work(tmp_path, monkeypatch):
    """n_fields or points_per_field a digit too large (15360 x 16000: 256 GiB) ran the machine out
    of memory while making the set, with nothing said; the engine's shards the same."""
    from woodcam.benchmark import make_training_set_many

    monkeypatch.setenv("WOODCAM_MAX_ALLOC_BYTES", "1000000")
    big = GTFSpec(**{**TINY, "n_fields": 200, "points_per_field": 100})   # 20,000 points: 2.2 MB
    made = []

    def training_set():
        made.append(1)
        return make_training_set_many(big, tmp_path / "shards", engine="local", workers=1, progress=False)

    for call in (lambda: train_gtf(big, tmp_path / "out", progress=False),
                 lambda: train_gtf(big, tmp_path / "out", progress=False, training_set=training_set),
                 lambda: make_training_set(big)):
        with pytest.raises(WoodcamError, match=r"the GTF training set \(200 fields x 100 points\) needs .* "
                                               r"MAX_ALLOC_BYTES.*lower n_fields or points_per_field"):
            call()
    assert not made and not (tmp_path / "out" / SPEC_NAME).exists()
    make_training_set(GTFSpec(**TINY))                                     # 512 points pass


def test_loading_the_model_leaves_the_callers_random_numbers_alone(tmp_path):
    """build_model seeded torch's global generator with the spec's seed, so every load_model
    (each neural fit) reset the caller's torch random stream to seed 0's."""
    torch.manual_seed(123)
    want = torch.rand(3)
    torch.manual_seed(123)
    load_model()
    np.testing.assert_array_equal(torch.rand(3).numpy(), want.numpy())
    a, b = build_model(GTFSpec(**TINY)), build_model(GTFSpec(**TINY))       # still seeded by the spec
    assert all(torch.equal(p, q) for p, q in zip(a.parameters(), b.parameters()))


def test_the_final_error_pass_has_its_bar(tmp_path, bars):
    """After the steps' bar closed at 100 %, the final error over the whole training set ran
    without one: 19.5 s on one thread for the committed spec's 2.46 M points."""
    spec = GTFSpec(**{**TINY, "n_fields": 130, "batch_fields": 4, "steps": 2})
    train_gtf(spec, tmp_path, progress=True)
    final = [b for b in bars if b.desc == "train gtf: final error"]
    assert len(final) == 1 and final[0].enabled and final[0].total == 3 and final[0].n == 3   # 130 fields: 3 of 64
    train_gtf(spec, tmp_path / "quiet", progress=False)
    assert not [b for b in bars if b.desc == "train gtf: final error"][-1].enabled
