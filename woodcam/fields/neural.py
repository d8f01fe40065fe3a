"""The seed's generic neural growth-time field (§3.2.1-3.2.2 and §3.2.5 of seed 000).

An auto-decoder MLP ``f_theta(c, gamma(p))`` (eq. 2) maps a latent code ``c`` and the cylindrical
encoding ``gamma`` (eq. 4) of a point ``p`` in the normalised trunk domain ``[-1, 1]^3`` (pith on
the ``z`` axis) to its growth time. The network and one latent code per training field are
trained jointly (eq. 3) on random fields of the eq. 7-9 family::

    GTF(x, y, z) = rho / r'(phi, z),   r'(phi, z) = (1 - (z+1)/2) r_-1(phi) + (z+1)/2 r_1(phi)

so growth time here is in *normalised units* (one unit of radius at ``r' = 1``); the fitter
(:mod:`woodcam.inference.neural`) maps block millimetres into this domain and scales the output
to years.

Design decisions (the seed leaves them open or we deliberately deviate):

* Encoding. Eq. 4 feeds ``(r, arccos(x/r), arcsin(y/r), z)``; ``arccos`` and ``arcsin`` each fold
  two half-planes onto one value (ambiguous) and have infinite slope at ``x/r = +-1``. We feed
  ``(r, x/r, y/r, z)`` instead, which carries the same angle without folding and is smooth in
  ``phi``, plus ``cos(k phi), sin(k phi)`` for ``k = 2 .. n_harmonics`` (computed from powers of
  ``(x + i y) / r``) because the radius functions have ~15 constraints per turn and a small MLP
  builds those frequencies slowly from ``(cos phi, sin phi)`` alone.
* Radial output head. The network output is ``f = r * (1 + h(c, gamma(p)))``: every field of the
  family is 0 on the pith and has the sharp cone ``rho / r'`` there, which a small MLP with
  smooth activations rounds off (the seed oversamples the pith region for this reason, and we
  keep that 20 % sampling); with the factor ``r`` the network only learns the smooth
  ``1 / r'(phi, z)``. ``h`` still sees ``r``, so fields that are not homogeneous in ``rho`` are
  representable.
* Size. 32-dim codes (seed: 50; 16 dims, fewer than the family's 30 radius constraints, left a
  5x larger training error), 4 x 128 softplus layers, 1,536 training fields x 1,600 points (seed:
  10,000), 40,000 steps of 64 fields x 32 points: 519 s on one shared CPU thread, final L1
  0.0010 normalised units (0.16 % of the growth time). Weights: 226 kB.
"""

from __future__ import annotations

import csv
import json
import time
from collections.abc import Callable
from dataclasses import asdict, dataclass, fields as dc_fields
from pathlib import Path

import numpy as np

from .._atomic import atomic_path, atomic_write, write_text
from .._readers import read_torch_state, torch_archive_problem
from .._threads import restores_torch_threads
from ..errors import WoodcamError, WoodcamWarning, require
from .radial import laplacian_smoother

#: Where the committed model lives (package data).
MODELS_DIR = Path(__file__).resolve().parent.parent / "models"
SPEC_NAME = "gtf_spec.json"
WEIGHTS_NAME = "gtf.pt"
LOG_NAME = "gtf_train_log.csv"
_CHECKPOINT_NAME = "gtf_checkpoint.pt"


#: Peak bytes per training point of :func:`make_training_set` (float64 points, the radius
#: functions' lookups and the float32 copies): tracemalloc measured 111 B a point on the
#: committed spec's 1,600 points a field (256 fields, 45 MB). The default set is 2.46 M points,
#: ~270 MB; a spec asking for more than ``MAX_ALLOC_BYTES`` is refused before any is made.
TRAINING_BYTES_PER_POINT = 112

#: Largest :attr:`GTFSpec.constraint_sigma`: the constraint values are clipped to ``[0.5, 1.5]``
#: (seed 000), so a sigma above 0.5 clips more than a third of them to the two bounds and the family
#: is no longer ``N(1, sigma)``; from sigma ~1 up every constraint is 0.5 or 1.5.
MAX_CONSTRAINT_SIGMA = 0.5

#: The :class:`GTFSpec` fields that are counts (integers >= 1; the seed >= 0).
_GTF_INTEGERS = ("seed", "n_fields", "points_per_field", "n_constraints", "radius_samples", "latent_dim",
                 "hidden", "layers", "n_harmonics", "batch_fields", "batch_points", "steps",
                 "checkpoint_every", "log_every")


@dataclass(frozen=True)
class GTFSpec:
    """Every hyper-parameter of the generic GTF model and its training run (JSON round trip).

    Attributes
    ----------
    seed : int
        Seeds the training fields, the sample points, the latent codes, the weights and the
        mini-batches; two runs with one spec give the same weights.
    n_fields, points_per_field : int
        Training set size, ``N`` GTFs times ``M`` points (seed 000: 10,000 x 1,600).
    pith_fraction : float
        Share of each field's points drawn from ``[-0.1, 0.1]^2 x [-1, 1]``, in ``[0, 1]`` (seed: 0.2).
    n_constraints, constraint_sigma : int, float
        Radius functions: ``N_c`` constraints from ``N(1, sigma)`` clipped to ``[0.5, 1.5]``;
        ``sigma`` in ``(0, MAX_CONSTRAINT_SIGMA]`` (seed: 15, 0.1).
    latent_dim, hidden, layers : int
        Code size, MLP width and number of hidden layers.
    n_harmonics : int
        Angular encoding carries ``cos(k phi), sin(k phi)`` for ``k = 1 .. n_harmonics``.
    w_reg : float
        Latent regularisation weight of eq. 3 (seed: ``alpha = 0.01^2``).
    lr_net, lr_latent : float
        Adam learning rates, decayed by a cosine to ``lr_floor`` times their value.
    batch_fields, batch_points : int
        Each step uses ``batch_fields`` fields and ``batch_points`` points of each.
    steps, checkpoint_every, log_every : int
    """

    seed: int = 0
    n_fields: int = 1536
    points_per_field: int = 1600
    pith_fraction: float = 0.2
    n_constraints: int = 15
    constraint_sigma: float = 0.1
    radius_samples: int = 360
    latent_dim: int = 32
    hidden: int = 128
    layers: int = 4
    n_harmonics: int = 6
    w_reg: float = 1e-4
    lr_net: float = 1e-3
    lr_latent: float = 1e-2
    lr_floor: float = 0.05
    batch_fields: int = 64
    batch_points: int = 32
    steps: int = 40000
    checkpoint_every: int = 1000
    log_every: int = 100

    def __post_init__(self):
        from .._checks import check_number

        # the integer counts were taken as any positive number and the seed not checked at all:
        # a seed of -1 or 4.5 fields was numpy's error after the spec was written
        fix = "fix it in the spec's JSON file"
        for f in dc_fields(self):
            v = getattr(self, f.name)
            if f.name in _GTF_INTEGERS:
                check_number(v, f"spec.{f.name}", lo=0 if f.name == "seed" else 1, integer=True, fix=fix)
            elif f.name == "pith_fraction":     # 0 (no pith points) is in the documented range
                check_number(v, "spec.pith_fraction", lo=0, hi=1, fix=fix)
            elif f.name == "constraint_sigma":
                # 0.5 at most: the constraints are clipped to [0.5, 1.5]; sigma 50 was taken and made
                # every constraint 0.5 or 1.5 (a two-valued family, not N(1, sigma))
                check_number(v, "spec.constraint_sigma", lo=0, hi=MAX_CONSTRAINT_SIGMA, lo_open=True,
                             fix=f"{fix} (the constraints are clipped to [0.5, 1.5]; seed 000 uses 0.1)")
            elif not (isinstance(v, (int, float)) and not isinstance(v, bool) and np.isfinite(v) and v > 0):
                raise WoodcamError(f"spec.{f.name} must be a positive number; got {v!r}; {fix}")
        if self.lr_floor > 1:   # the cosine then rose from the rate to lr_floor times it
            raise WoodcamError(f"spec.lr_floor must be in (0, 1] (the learning rates decay to lr_floor times "
                               f"their value); got {self.lr_floor!r}; {fix}")
        if self.n_constraints > self.radius_samples:   # was the smoother's "m=1 samples cannot hold ..."
            raise WoodcamError(f"spec.n_constraints must be at most spec.radius_samples ({self.radius_samples}: the "
                               f"constraints are distinct samples of each radius function); got "
                               f"{self.n_constraints}; {fix}")

    def to_dict(self) -> dict:
        return asdict(self)

    @classmethod
    def from_dict(cls, d: dict) -> "GTFSpec":
        known = {f.name for f in dc_fields(cls)}
        unknown = set(d) - known
        if unknown:
            raise WoodcamError(f"GTF spec has unknown keys {sorted(unknown)}; known: {sorted(known)}")
        return cls(**d)

    def save(self, path) -> Path:
        from .._atomic import write_text

        return write_text(path, json.dumps(self.to_dict(), indent=2) + "\n")

    @classmethod
    def load(cls, path) -> "GTFSpec":
        from .._readers import read_json_object

        d = read_json_object(path, "GTF spec")
        try:
            return cls.from_dict(d)
        except WoodcamError as err:     # which file: a spec is read from OUT or --spec
            raise WoodcamError(f"GTF spec {str(path)!r}: {err}") from err


# ---------------------------------------------------------------------------------------------
# Training data: the eq. 7-9 family, vectorised over many fields


def random_radius_samples(rng: np.random.Generator, count: int, n_constraints: int = 15,
                          sigma: float = 0.1, m: int = 360) -> np.ndarray:
    """``(count, m)`` radius functions, like ``RadiusFunction.random`` ``count`` times."""
    smooth = laplacian_smoother(n_constraints, m)
    vals = np.clip(rng.normal(1.0, sigma, (count, n_constraints)), 0.5, 1.5)
    return vals @ smooth.T


def family_gtf(points: np.ndarray, r_minus: np.ndarray, r_plus: np.ndarray) -> np.ndarray:
    """Eq. 7-9 in normalised units for many fields at once.

    Parameters
    ----------
    points : (n_fields, n, 3) float
        Normalised domain points (pith on ``z``, ``z`` in ``[-1, 1]``, clamped beyond).
    r_minus, r_plus : (n_fields, m) float
        Radius functions at ``z = -1`` and ``z = 1`` sampled at ``phi = 2 pi i / m``.

    Returns
    -------
    (n_fields, n) float growth time ``rho / r'(phi, z)``; matches
    :class:`~woodcam.fields.radial.RadialScalingField` with ring width 1, half length 1.
    """
    x, y, z = points[..., 0], points[..., 1], points[..., 2]
    m = r_minus.shape[1]
    t = np.mod(np.arctan2(x, y), 2 * np.pi) * (m / (2 * np.pi))
    i0 = np.floor(t).astype(np.int64)
    f = t - i0
    i0 %= m
    i1 = (i0 + 1) % m
    rows = np.arange(len(points))[:, None]
    rm = r_minus[rows, i0] * (1 - f) + r_minus[rows, i1] * f
    rp = r_plus[rows, i0] * (1 - f) + r_plus[rows, i1] * f
    w = (np.clip(z, -1.0, 1.0) + 1.0) * 0.5
    return np.hypot(x, y) / np.maximum((1 - w) * rm + w * rp, 1e-3)


#: The fields of :class:`GTFSpec` that :func:`make_training_set` reads: two specs equal in these
#: have the same training set (the network and optimiser settings do not change it).
TRAINING_SET_FIELDS = ("seed", "n_fields", "points_per_field", "pith_fraction", "n_constraints",
                       "constraint_sigma", "radius_samples")


def make_training_set(spec: GTFSpec) -> tuple[np.ndarray, np.ndarray]:
    """Sample the training pairs of §3.2.5: ``points (N, M, 3)`` and ``values (N, M)``, float32."""
    return make_training_shard(spec, 0, spec.n_fields)


def check_training_set_size(spec: GTFSpec, n_fields: int | None = None) -> None:
    """Refuse, before any allocation, a training set of ``n_fields`` (default ``spec.n_fields``)
    fields of ``spec.points_per_field`` points that needs more than ``MAX_ALLOC_BYTES``
    (:data:`TRAINING_BYTES_PER_POINT`): a spec with a digit too many (15360 fields x 16000
    points) ran the machine out of memory with nothing said."""
    from ..limits import check_limit

    n = spec.n_fields if n_fields is None else n_fields
    check_limit("MAX_ALLOC_BYTES", float(n) * spec.points_per_field * TRAINING_BYTES_PER_POINT,
                f"the GTF training set ({n} fields x {spec.points_per_field} points)",
                "lower n_fields or points_per_field in the spec")


def make_training_shard(spec: GTFSpec, start: int, stop: int) -> tuple[np.ndarray, np.ndarray]:
    """Fields ``start .. stop - 1`` of :func:`make_training_set`, bit for bit, computed alone.

    The radius functions of all ``N`` fields are drawn (``2 N N_c`` normals, cheap; the normal
    sampler uses a variable number of raw draws, so it cannot be skipped), then the generator is
    advanced past the ``3 M start`` uniforms of the earlier fields (a uniform double takes exactly
    one 64-bit draw of PCG64), so shards can be made in parallel and concatenated.
    """
    n, mp = spec.n_fields, spec.points_per_field
    check_training_set_size(spec, stop - start if 0 <= start < stop <= n else n)
    if not 0 <= start < stop <= n:
        raise WoodcamError(f"shard must satisfy 0 <= start < stop <= n_fields = {n}; got {start}..{stop}")
    rng = np.random.default_rng([spec.seed, 1])
    r_minus = random_radius_samples(rng, n, spec.n_constraints, spec.constraint_sigma, spec.radius_samples)
    r_plus = random_radius_samples(rng, n, spec.n_constraints, spec.constraint_sigma, spec.radius_samples)
    r_minus, r_plus = r_minus[start:stop], r_plus[start:stop]
    rng.bit_generator.advance(3 * mp * start)
    pts = rng.uniform(-1.0, 1.0, (stop - start, mp, 3))
    n_pith = int(round(spec.pith_fraction * mp))
    pts[:, :n_pith, :2] *= 0.1  # [-0.1, 0.1]^2 x [-1, 1] near the pith
    vals = family_gtf(pts, r_minus, r_plus)
    return pts.astype(np.float32), vals.astype(np.float32)


# ---------------------------------------------------------------------------------------------
# Model


def _torch():
    return require("torch", "learn", "the neural growth field")


def encode(p, n_harmonics: int):
    """Cylindrical encoding (eq. 4, smooth variant), ``(..., 3) -> (..., 2 + 2 * n_harmonics)``.

    Returns ``(r, z, cos phi, sin phi, ..., cos(k phi), sin(k phi))`` with ``cos phi = x / r`` and
    ``sin phi = y / r`` (see the module docstring for why not arccos/arcsin). At the pith the
    angle is undefined; a tiny ``eps`` in ``r`` makes the angular features go to 0 there
    smoothly, and the radial output head multiplies them by ``r ~ 0`` anyway.
    """
    torch = _torch()
    x, y, z = p[..., 0], p[..., 1], p[..., 2]
    r = torch.sqrt(x * x + y * y + 1e-12)
    c1, s1 = x / r, y / r
    feats = [r, z, c1, s1]
    ck, sk = c1, s1
    for _ in range(1, n_harmonics):
        ck, sk = ck * c1 - sk * s1, sk * c1 + ck * s1  # (c + i s)^k by repeated multiplication
        feats += [ck, sk]
    return torch.stack(feats, dim=-1)


def build_model(spec: GTFSpec):
    """The auto-decoder network ``f_theta(c, gamma(p))`` of eq. 2 as a ``torch.nn.Module``."""
    torch = _torch()
    nn = torch.nn

    class GTFNet(nn.Module):
        """``forward(codes (..., latent_dim), points (..., 3)) -> growth time (...)``."""

        def __init__(self):
            super().__init__()
            self.n_harmonics = spec.n_harmonics
            self.latent_dim = spec.latent_dim
            d_in = spec.latent_dim + 2 + 2 * spec.n_harmonics
            mods, d = [], d_in
            for _ in range(spec.layers):
                mods += [nn.Linear(d, spec.hidden), nn.Softplus(beta=10.0)]
                d = spec.hidden
            last = nn.Linear(d, 1)
            nn.init.zeros_(last.weight)  # start at f = r, the mean field of the family
            nn.init.zeros_(last.bias)
            mods.append(last)
            self.mlp = nn.Sequential(*mods)

        def forward(self, codes, points):
            g = encode(points, self.n_harmonics)
            codes = codes.expand(*g.shape[:-1], codes.shape[-1])
            h = self.mlp(torch.cat([codes, g], dim=-1))[..., 0]
            return g[..., 0] * (1.0 + h)

    # the spec's seed draws the initial weights, on a fork of torch's generator: seeded
    # globally, every load_model (each neural fit) reset the caller's torch random numbers to
    # the same stream, seed 0's
    with torch.random.fork_rng(devices=[]):
        torch.manual_seed(spec.seed)
        return GTFNet()


def load_model(model_dir=None):
    """The trained generic model and its spec: ``(net, spec)``, net in eval mode, float32.

    ``model_dir`` defaults to the package's ``woodcam/models`` (``gtf_spec.json`` + ``gtf.pt``).
    """
    d = Path(model_dir) if model_dir is not None else MODELS_DIR
    spec_path, w_path = d / SPEC_NAME, d / WEIGHTS_NAME
    if not (spec_path.is_file() and w_path.is_file()):
        raise WoodcamError(f"model_dir {d}: needs {SPEC_NAME} and {WEIGHTS_NAME}; "
                           f"train one with 'woodcam train gtf --out {d}'")
    # a broken file was torch's EOFError, OSError or a many-line RuntimeError (another net's
    # weights): one line naming the file and the fix instead
    fix = (f"restore the folder's {SPEC_NAME} and {WEIGHTS_NAME} (the packaged model: reinstall woodcam or "
           f"check out woodcam/models) or retrain them with 'woodcam train gtf --spec SPEC --out {d}'")
    try:
        spec = GTFSpec.load(spec_path)
    except WoodcamError as err:
        raise WoodcamError(f"{err}; {fix}") from err
    net = build_model(spec)
    state = read_torch_state(w_path, "GTF model weights", net.state_dict(), fix)
    net.load_state_dict({k: v.float() for k, v in state.items()})
    net.eval()
    for prm in net.parameters():
        prm.requires_grad_(False)
    return net, spec


# ---------------------------------------------------------------------------------------------
# Training (eq. 3)


def _plain(obj):
    """``obj`` with numpy scalars turned into Python numbers (containers walked, tensors kept), so
    that ``torch.load(weights_only=True)`` can read it back (the learning-rate schedule yields
    numpy floats)."""
    if isinstance(obj, dict):
        return type(obj)((k, _plain(v)) for k, v in obj.items())
    if isinstance(obj, (list, tuple)):
        return type(obj)(_plain(v) for v in obj)
    if isinstance(obj, np.generic):
        return obj.item()
    return obj


def _load_checkpoint(torch, ckpt: Path, spec: GTFSpec) -> dict:
    """A training checkpoint, loaded with ``weights_only=True``: tensors and plain data only, so a
    crafted file cannot run code (a pickle that needs anything else is refused)."""
    import pickle

    fix = "delete it or pass resume=False (CLI: --no-resume) to start afresh"
    try:
        problem = torch_archive_problem(ckpt)
    except OSError as err:
        raise WoodcamError(f"checkpoint {ckpt} cannot be read ({err.strerror}); {fix}") from err
    if problem:  # a run killed mid-write never leaves this (atomic writes): a copy or a disk did
        what = "empty" if problem == "empty" else "cut short or another kind of file (not a zip archive)"
        raise WoodcamError(f"checkpoint {ckpt} is {what}; {fix}")
    try:
        state = torch.load(ckpt, map_location="cpu", weights_only=True)
    except (pickle.UnpicklingError, RuntimeError, EOFError, OSError, ValueError,
            AttributeError, TypeError) as err:
        raise WoodcamError(
            f"checkpoint {ckpt} is not a woodcam training checkpoint of tensors and plain data "
            f"({type(err).__name__}); it was refused, nothing in it was run. Delete it or pass "
            "resume=False (CLI: --no-resume) to start afresh") from err
    keys = {"spec", "net", "codes", "opt", "step", "elapsed", "log"}
    if not isinstance(state, dict) or not keys <= set(state):
        raise WoodcamError(f"checkpoint {ckpt} lacks the keys {sorted(keys)}; delete it or pass "
                           "resume=False")
    if state["spec"] != spec.to_dict():
        theirs = state["spec"] if isinstance(state["spec"], dict) else {}
        raise WoodcamError(f"checkpoint {ckpt} was written for another spec; delete it or "
                           f"pass resume=False (CLI: --no-resume) (spec differs in "
                           f"{sorted(k for k in spec.to_dict() if theirs.get(k) != spec.to_dict()[k])})")
    return state


def _lr_scale(step: int, total: int, floor: float) -> float:
    """Cosine decay from 1 to ``floor`` over ``total`` steps (a function of the step alone, so a
    resumed run follows the same schedule)."""
    t = min(step / max(total, 1), 1.0)
    return floor + (1 - floor) * 0.5 * (1 + np.cos(np.pi * t))


@restores_torch_threads
def train_gtf(spec: GTFSpec, out_dir, *, steps: int | None = None, resume: bool = True,
              progress: bool = True, threads: int = 1,
              training_set: tuple[np.ndarray, np.ndarray] | Callable[[], tuple[np.ndarray, np.ndarray]]
              | None = None) -> dict:
    """Train the generic model (eq. 3) and write spec, weights and log into ``out_dir``.

    A checkpoint (network, latent codes, optimiser, log) is written every
    ``spec.checkpoint_every`` steps and at the end; with ``resume`` a run continues from it.
    Mini-batches are drawn from a generator seeded by ``(seed, step)``, so a run stopped and
    resumed gives the same weights as one straight run.

    Parameters
    ----------
    steps : int, optional
        Stop after this many steps in total (default ``spec.steps``); the learning-rate
        schedule always follows ``spec.steps``.
    threads : int
        torch CPU threads. 1 by default: the mini-batch matrices are small, and on a shared
        machine two OpenMP threads contending with other processes ran 5-40x slower than one.
    training_set : (points (N, M, 3), values (N, M)) float32, optional
        :func:`make_training_set` of ``spec`` made elsewhere (e.g. in shards on many workers
        by :func:`woodcam.benchmark.make_training_set_many`), or a function of no arguments
        that returns it, called only once the checkpoint was checked (a run refused for another
        spec then spends nothing on the set); default: made here.

    Returns
    -------
    dict with ``step (k,) int``, ``loss (k,)`` (L1 of the logged steps, normalised units),
    ``time_s (k,)`` (cumulative training seconds), ``final_l1`` (mean L1 over the whole
    training set, normalised units), ``final_rel`` (mean |error| / value over points with
    ``value > 0.1``) and ``train_s``.
    """
    torch = _torch()
    torch.set_num_threads(int(threads))
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    total = spec.steps if steps is None else int(steps)
    if total < 0:
        raise WoodcamError(f"steps must be >= 0; got {steps!r}")
    if spec.batch_fields > spec.n_fields:  # was numpy's "Cannot take a larger sample than population"
        raise WoodcamError(f"spec.batch_fields must be at most spec.n_fields ({spec.n_fields}) to train: each "
                           f"step draws that many different fields; got {spec.batch_fields}; lower it or raise "
                           "n_fields in the spec")
    ckpt = out / _CHECKPOINT_NAME
    check_training_set_size(spec)  # before a checkpoint is read, or shards made on an engine
    # read (and refuse) a checkpoint before minutes of work building the training set
    state = _load_checkpoint(torch, ckpt, spec) if resume and ckpt.is_file() else None
    if state is not None and state["step"] > total:
        # 'train gtf --steps 20' over a 50-step checkpoint wrote the 50-step weights, said only
        # "trained 50 steps"
        import warnings

        warnings.warn(WoodcamWarning(
            f"the checkpoint {ckpt} is at step {state['step']}, past steps={total}: nothing is trained and its "
            f"weights are written as they are; pass resume=False (CLI: --no-resume) to train {total} steps "
            "afresh"), stacklevel=2)

    if callable(training_set):
        training_set = training_set()
    if training_set is None:
        pts_np, vals_np = make_training_set(spec)
    else:
        pts_np, vals_np = (np.asarray(a, np.float32) for a in training_set)
        want = (spec.n_fields, spec.points_per_field)
        if pts_np.shape != want + (3,) or vals_np.shape != want:
            raise WoodcamError(f"training_set must be points {want + (3,)} and values {want} for "
                               f"this spec; got {pts_np.shape} and {vals_np.shape}")
    pts, vals = torch.from_numpy(pts_np), torch.from_numpy(vals_np)
    net = build_model(spec)
    gen = torch.Generator().manual_seed(spec.seed + 7)
    codes = torch.nn.Parameter(torch.randn(spec.n_fields, spec.latent_dim, generator=gen)
                               / np.sqrt(spec.latent_dim))
    opt = torch.optim.Adam([{"params": net.parameters(), "lr": spec.lr_net},
                            {"params": [codes], "lr": spec.lr_latent}])
    log: list[tuple[int, float, float]] = []
    step, elapsed = 0, 0.0
    if state is not None:
        net.load_state_dict(state["net"])
        with torch.no_grad():
            codes.copy_(state["codes"])
        opt.load_state_dict(state["opt"])
        step, elapsed, log = state["step"], state["elapsed"], [tuple(r) for r in state["log"]]

    def save_checkpoint():
        # tensors and plain data only (loaded back with weights_only=True); atomic, so a run
        # killed while saving keeps the previous checkpoint
        with atomic_path(ckpt) as tmp:
            torch.save(_plain({"spec": spec.to_dict(), "net": net.state_dict(),
                               "codes": codes.detach(), "opt": opt.state_dict(), "step": step,
                               "elapsed": elapsed, "log": [list(r) for r in log]}), tmp)

    from .._progress import progress_bar

    bar = None
    if progress:
        bar = progress_bar(total=total, initial=min(step, total), desc="train gtf", unit="step")
    t0 = time.perf_counter()
    base = elapsed
    n_f, n_p = spec.n_fields, spec.points_per_field
    while step < total:
        for group, lr in zip(opt.param_groups, (spec.lr_net, spec.lr_latent)):
            group["lr"] = lr * _lr_scale(step, spec.steps, spec.lr_floor)
        rng = np.random.default_rng([spec.seed, 2, step])
        fi = torch.from_numpy(rng.choice(n_f, spec.batch_fields, replace=False))
        pi = torch.from_numpy(rng.integers(0, n_p, (spec.batch_fields, spec.batch_points)))
        p = pts[fi[:, None], pi]
        g = vals[fi[:, None], pi]
        c = codes[fi]
        pred = net(c[:, None, :], p)
        l1 = (pred - g).abs().mean()
        loss = l1 + spec.w_reg * (c * c).sum(dim=1).mean()
        opt.zero_grad(set_to_none=True)
        loss.backward()
        opt.step()
        step += 1
        elapsed = base + time.perf_counter() - t0
        if step % spec.log_every == 0 or step == total:
            log.append((step, float(l1.detach()), elapsed))
            if bar is not None:
                bar.set_postfix(l1=f"{log[-1][1]:.4f}", refresh=False)
        if bar is not None:
            bar.update(1)
        if step % spec.checkpoint_every == 0 or step == total:
            save_checkpoint()
    if bar is not None:
        bar.close()
    save_checkpoint()

    # Final error over the whole training set, each field with its own code: 19.5 s on one
    # thread for the committed spec (2.46 M points), after the training bar had closed at 100 %
    net.eval()
    with torch.no_grad():
        errs, rels = [], []
        for i in progress_bar(range(0, n_f, 64), desc="train gtf: final error", unit="batch",
                              enabled=progress):
            pr = net(codes[i:i + 64, None, :], pts[i:i + 64])
            e = (pr - vals[i:i + 64]).abs()
            errs.append(e.mean(dim=1))
            m = vals[i:i + 64] > 0.1
            rels.append((e[m] / vals[i:i + 64][m]).sum() / max(int(m.sum()), 1) * torch.ones(1))
        final_l1 = float(torch.cat(errs).mean())
        final_rel = float(torch.cat(rels).mean())
    state = {k: v.detach().clone() for k, v in net.state_dict().items()}
    # the spec with the weights, at the end: written at the start, it stood beside the previous
    # gtf.pt for the whole run, and for good when the run failed or was killed (a new seed or
    # learning rate loaded those weights under a spec that never made them)
    with atomic_path(out / WEIGHTS_NAME) as tmp:
        torch.save(state, tmp)
    spec.save(out / SPEC_NAME)
    with atomic_write(out / LOG_NAME, "w", newline="") as fh:
        w = csv.writer(fh)
        w.writerow(["step", "l1", "time_s"])
        for s, l, t in log:
            w.writerow([s, f"{l:.6g}", f"{t:.2f}"])
    write_text(out / "gtf_train_summary.json", json.dumps(
        {"steps": step, "train_s": round(elapsed, 1), "final_l1": final_l1, "final_rel": final_rel,
         "code_norm_mean": float(codes.detach().norm(dim=1).mean()),
         "code_std": float(codes.detach().std())}, indent=2) + "\n")
    arr = np.array(log, dtype=float).reshape(-1, 3)
    return {"step": arr[:, 0].astype(int), "loss": arr[:, 1], "time_s": arr[:, 2],
            "final_l1": final_l1, "final_rel": final_rel, "train_s": elapsed,
            "net": net, "codes": codes.detach().numpy().copy()}
