"""The small learned ring detector: a tiny U-Net trained from scratch on woodcam's own synthetic faces.

Input: the flattened, contrast-normalised luminance of a face photo (:func:`woodcam.detect.rings._normalise`,
``(h, w)`` float, the same as the classical detector sees). Output: ``(h, w)`` probability that a
pixel lies within about a pixel of a ring boundary. Ring lines are the ridge of that map across
the local ring normal (from the classical detector's orientation field), found with the same
sub-pixel contour code as the classical detector, so the result is a
:class:`~woodcam.detect.rings.RingDetection` like the classical one.

Training (:func:`train_ring_net`, ``woodcam train rings``; the faces come from
:func:`woodcam.synth.ring_training_faces`, which sits above this package): faces of synthetic cubes (random
eccentric logs, every sawing pattern, a quarter of them knotted logs of seed 001/003) rendered by
:func:`woodcam.synth.synth_block`, with photo-style augmentation: colour and exposure, blur,
noise, JPEG, lighting gradients, dark pores and ray streaks. The target is the exact distance
to the true ring lines (the integer iso-lines of the true field), ``exp(-(d / sigma)^2)``.
The quilted styles (opt-in; the committed net is ``"mixed"``) paint training faces with real
photos' texture placed by ring phase (:mod:`woodcam.detect.quilt`; the photos are read when
training, never at run time). Everything is seeded by :attr:`RingNetSpec.seed`; the spec, the weights and a CSV log are
written together. The committed model lives in ``woodcam/models/rings.*``.

Members (opt-in, issue 13; the committed folder holds the main net only): a models folder may hold a second
net beside ``rings.*``, the ``"quilted"`` member ``rings_quilted.*`` (a net of a quilted style,
``woodcam train rings --member quilted``); :func:`ring_probability` is then the weighted mean of
the members' probabilities (:data:`QUILTED_MEMBER_WEIGHT`), and everything downstream runs on it.
"""

from __future__ import annotations

import csv
import json
import time
from dataclasses import asdict, dataclass
from dataclasses import fields as dc_fields
from pathlib import Path
from typing import Literal, get_args

import numpy as np

from .._atomic import atomic_path, atomic_write, write_text
from .._readers import torch_state
from .._threads import restores_torch_threads
from ..errors import WoodcamError, require

MODELS_DIR = Path(__file__).resolve().parent.parent / "models"
SPEC_NAME = "rings_spec.json"
WEIGHTS_NAME = "rings.pt"
LOG_NAME = "rings_train_log.csv"
#: The nets a models folder may hold (module docstring): ``"main"`` (``rings.*``, always) and
#: the optional ``"quilted"`` member (``rings_quilted.*``, a net of a :data:`QUILTED_STYLES` style).
RING_NET_MEMBERS = ("main", "quilted")
#: Weight of the quilted member: the folder's probability is ``(1 - w) p_main + w p_quilted``.
#: Issue 13, the committed net with the quilted v2 fold nets, blind (each fold's net on the other
#: fold's faces): the arithmetic mean (0.5) was the only rule tried that kept both bars: the 12
#: real faces' ridge 0.464 / 0.734 within 2 / 5 px (v2 alone 0.475 / 0.754, the committed net
#: 0.411 / 0.633) and the synthetic test's realistic faces (seeds 1000-1001, snap) 0.755 / 0.752
#: (committed 0.791, v2 0.723 / 0.726); 0.67 gave 0.468 / 0.745 but 0.743 / 0.746, the
#: geometric mean 0.769 / 0.769 but 0.453 / 0.694.
QUILTED_MEMBER_WEIGHT = 0.5
#: Per style, the colour of training cube ``i``: entry ``i % len(...)``.
_CUBE_STYLES = {"plain": ("plain",), "realistic": ("realistic",), "mixed": ("plain", "realistic", "realistic"),
                "quilted": ("plain", "quilted", "quilted"), "mixed-quilted": ("plain", "realistic", "quilted"),
                "quilted-softwood": ("plain", "quilted", "softwood", "quilted", "quilted")}
#: Colours of the training faces (:attr:`RingNetSpec.style`): the styles above, one home.
TRAINING_STYLES = tuple(_CUBE_STYLES)
#: The styles that paint some training cubes with real photos' texture (need ``texture_samples``).
QUILTED_STYLES = ("quilted", "mixed-quilted", "quilted-softwood")


def cube_style(style: str, i: int) -> str:
    """The colour (``"plain"``, ``"realistic"`` (softwood or oak by ``i``'s parity), ``"softwood"``
    (realistic softwood) or ``"quilted"``) of training cube ``i`` of a
    :class:`RingNetSpec` of ``style``."""
    kinds = _CUBE_STYLES[style]
    return kinds[i % len(kinds)]


def member_files(member: str = "main") -> tuple[str, str, str]:
    """The spec, weights and training-log file names of a models folder's ``member``
    (:data:`RING_NET_MEMBERS`): ``rings_spec.json``, ``rings.pt``, ``rings_train_log.csv`` for
    ``"main"``; ``rings_quilted_spec.json``, ``rings_quilted.pt``, ... for ``"quilted"``."""
    if member not in RING_NET_MEMBERS:
        raise WoodcamError(f"ring net member must be one of {', '.join(RING_NET_MEMBERS)}; got {member!r}")
    if member == "main":
        return SPEC_NAME, WEIGHTS_NAME, LOG_NAME
    return f"rings_{member}_spec.json", f"rings_{member}.pt", f"rings_{member}_train_log.csv"


def check_trainable(spec: RingNetSpec, face_shape: tuple[int, int] | None = None) -> None:
    """Refuse a ``spec`` whose training crops (``crop_px``) do not fit in its training faces
    (``face_shape`` ``(h, w)`` px, default ``face_px`` square): numpy's "high <= 0" once the
    faces were made (a spec of small faces is fine for making faces alone); or whose faces
    need more than ``MAX_ALLOC_BYTES`` or are larger than ``MAX_FACE_PX`` (:mod:`woodcam.limits`)."""
    from ..limits import check_limit

    # the faces are kept whole as inputs and targets, float32: 8 bytes a pixel at the least (each
    # cube's synthesis needs more); 4096 cubes of 2048 px asked for 824 GB with nothing said
    check_limit("MAX_FACE_PX", spec.face_px, "ring net spec face_px", "lower face_px in the spec")
    check_limit("MAX_ALLOC_BYTES", 6.0 * spec.n_blocks * spec.face_px ** 2 * 8,
                f"the ring net's training faces ({spec.n_blocks} cubes x 6 faces of {spec.face_px} px)",
                "lower n_blocks or face_px in the spec")
    h, w = face_shape or (spec.face_px, spec.face_px)
    if spec.crop_px > min(h, w):
        raise WoodcamError(f"ring net spec crop_px must be at most the training faces' size ({h} x {w} px, "
                           f"face_px) to train; got {spec.crop_px}; lower crop_px or raise face_px in the spec")


def check_member(spec: RingNetSpec, member: str, what: str = "member") -> None:
    """Refuse a ``member`` that ``spec`` cannot be: the quilted member is a net of a quilted style
    (its combination weight was measured for those). ``what`` names the argument in the message."""
    member_files(member)
    if member == "quilted" and spec.style not in QUILTED_STYLES:
        raise WoodcamError(f"{what} quilted needs a spec of a quilted style ({', '.join(QUILTED_STYLES)}, with "
                           f"texture_samples); got style {spec.style!r}; train it with --spec naming such a style, "
                           f"or leave out {what} for the main net")


@dataclass(frozen=True)
class RingNetSpec:
    """Every hyper-parameter of the ring net and its training run (JSON round trip).

    Attributes
    ----------
    seed : seeds the synthetic blocks, the augmentation, the weights and the batches.
    n_blocks, face_px : training cubes (six faces each) and their face size (px).
    target_sigma_px : width of the target line ``exp(-(d / sigma)^2)``.
    width : channels of the first level (doubled per level, three levels).
    crop_px, batch, steps, lr : training crops, batch size, Adam steps and learning rate (cosine decay).
    max_train_s : stop after this many seconds of training (the machine is shared). A wall-clock
        stop: a run it ends takes as many steps as the machine gives it, so two runs of one spec
        give the same weights only when both end at ``steps`` (the committed net stopped at 2,593
        of 5,000). To repeat a stopped run, set ``steps`` to its log's last ``step`` + 1 and
        ``max_train_s`` above its time (the cosine schedule then follows the new ``steps``, so
        it is a rerun of the same length, not of the same schedule).
    style : the training faces' colour (:data:`TRAINING_STYLES`): ``"plain"``, woodcam's built-in
        wood colour (a broad latewood band ending in a step at the boundary); ``"realistic"``,
        :class:`woodcam.synth.photos._RealisticWood` (narrow softwood latewood darkest at the
        boundary, or ring-porous oak whose pore band starts at it; rays, figure, faint rings),
        softwood and oak on alternate cubes; ``"mixed"``: every third cube plain, the others
        realistic; ``"quilted"``: every third cube plain, the others painted with real photos'
        texture placed by ring phase (:mod:`woodcam.detect.quilt`), spruce-like and oak-like
        cubes alternating by ``texture_samples``; ``"mixed-quilted"``: plain, realistic and
        quilted cubes in turn; ``"quilted-softwood"``: of every five cubes one plain, one
        realistic softwood and three quilted (:func:`cube_style`). The target is the true ring
        boundary on every style.
    texture_samples : for the quilted styles (:data:`QUILTED_STYLES`) only (refused otherwise):
        Mokume sample folders whose six face photos are the textures, relative to the shared data
        folder (``$WOODCAM_SHARED_DATA``), cube ``i`` of the training set painted from sample
        ``i % len(texture_samples)``. Read when the training faces are made, never at run time.
    """

    seed: int = 0
    n_blocks: int = 8
    face_px: int = 192
    target_sigma_px: float = 1.2
    width: int = 8
    crop_px: int = 64
    batch: int = 8
    steps: int = 1500
    lr: float = 2e-3
    max_train_s: float = 660.0
    log_every: int = 25
    style: str = "plain"
    texture_samples: tuple[str, ...] = ()

    def __post_init__(self) -> None:
        from .._checks import check_number

        # the numbers were not checked: 'woodcam train rings --spec S' with n_blocks 0, steps 0,
        # width 0, seed -1, log_every 0, crop_px 30 (not a multiple of 4: the U-Net's levels) or
        # above face_px failed in numpy's or torch's words, an "internal error", after minutes of faces
        fix = "fix it in the spec's JSON file"
        for name in ("seed", "n_blocks", "face_px", "width", "crop_px", "batch", "steps", "log_every"):
            check_number(getattr(self, name), f"ring net spec {name}", lo=0 if name == "seed" else 1,
                         integer=True, fix=fix)
        for name in ("target_sigma_px", "lr", "max_train_s"):
            check_number(getattr(self, name), f"ring net spec {name}", lo=0, lo_open=True, fix=fix)
        if self.crop_px % 4:
            raise WoodcamError(f"ring net spec crop_px must be a multiple of 4 (the net halves a crop twice); "
                               f"got {self.crop_px}; {fix}")
        if self.style not in TRAINING_STYLES:
            raise WoodcamError(f"ring net spec style must be one of {', '.join(TRAINING_STYLES)}; "
                               f"got {self.style!r}")
        samples = self.texture_samples
        if isinstance(samples, str) or not all(isinstance(x, str) and x for x in samples):
            raise WoodcamError(f"ring net spec texture_samples must be a list of sample folders (e.g. "
                               f"[\"mokume/H11\"]); got {samples!r}")
        object.__setattr__(self, "texture_samples", tuple(samples))   # JSON gives a list
        if (self.style in QUILTED_STYLES) != bool(self.texture_samples):
            raise WoodcamError(f"ring net spec texture_samples go with styles {', '.join(QUILTED_STYLES)} (their "
                               f"real texture photos) and only with them; got style {self.style!r} and texture_samples "
                               f"{list(self.texture_samples)}")

    @classmethod
    def load(cls, path) -> RingNetSpec:
        from .._readers import read_json_object

        d = read_json_object(path, "ring net spec")
        names = {f.name for f in dc_fields(cls)}
        bad = set(d) - names
        if bad:
            raise WoodcamError(f"ring net spec {str(path)!r} has unknown keys {sorted(bad)}; allowed: {sorted(names)}")
        try:
            return cls(**d)
        except WoodcamError as err:     # which file: --spec or a models folder's
            raise WoodcamError(f"{str(path)!r}: {err}") from err

    def save(self, path) -> None:
        write_text(path, json.dumps(asdict(self), indent=1))


def _net(spec: RingNetSpec):
    torch = require("torch", "learn", "the learned ring detector")
    nn = torch.nn

    def block(i, o):
        return nn.Sequential(nn.Conv2d(i, o, 3, padding=1), nn.BatchNorm2d(o), nn.ReLU(inplace=True),
                             nn.Conv2d(o, o, 3, padding=1), nn.BatchNorm2d(o), nn.ReLU(inplace=True))

    class RingUNet(nn.Module):
        """Three-level U-Net, ``(b, 1, h, w)`` -> logits ``(b, 1, h, w)``; h, w multiples of 4."""

        def __init__(self, w: int):
            super().__init__()
            self.e1, self.e2, self.e3 = block(1, w), block(w, 2 * w), block(2 * w, 4 * w)
            self.up2, self.d2 = nn.ConvTranspose2d(4 * w, 2 * w, 2, stride=2), block(4 * w, 2 * w)
            self.up1, self.d1 = nn.ConvTranspose2d(2 * w, w, 2, stride=2), block(2 * w, w)
            self.out = nn.Conv2d(w, 1, 1)
            self.pool = nn.MaxPool2d(2)

        def forward(self, x):
            a = self.e1(x)
            b = self.e2(self.pool(a))
            c = self.e3(self.pool(b))
            b = self.d2(torch.cat([self.up2(c), b], 1))
            a = self.d1(torch.cat([self.up1(b), a], 1))
            return self.out(a)

    return RingUNet(spec.width)


# -- training data ------------------------------------------------------------------------------------

def _augment(photo: np.ndarray, rng: np.random.Generator) -> np.ndarray:
    """Photo-style augmentation of an ``(h, w, 3)`` uint8 face: colour and exposure, lighting
    gradient, pores and ray streaks, blur, noise, JPEG."""
    import io

    from PIL import Image
    from scipy import ndimage

    h, w, _ = photo.shape
    a = photo.astype(np.float32) / 255.0
    a = a * rng.uniform(0.6, 1.3) * rng.uniform(0.85, 1.15, 3)                 # exposure, white balance
    a = (a - a.mean()) * rng.uniform(0.5, 1.5) + a.mean()                       # contrast
    rr, cc = np.meshgrid(np.linspace(-1, 1, h), np.linspace(-1, 1, w), indexing="ij")
    g = (1 + rng.uniform(-0.25, 0.25) * rr + rng.uniform(-0.25, 0.25) * cc
         - rng.uniform(0, 0.3) * (rr ** 2 + cc ** 2) / 2)
    a = a * g[..., None]
    if rng.uniform() < 0.6:                                                     # pores: dark specks
        n = int(rng.uniform(0.002, 0.02) * h * w)
        idx = rng.integers(0, [h, w], size=(n, 2))
        dark = np.zeros((h, w), np.float32)
        dark[idx[:, 0], idx[:, 1]] = rng.uniform(0.2, 0.6, n)
        dark = ndimage.gaussian_filter(dark, rng.uniform(0.5, 1.2)) * 3
        a = a * (1 - np.clip(dark, 0, 0.7))[..., None]
    if rng.uniform() < 0.4:                                                     # rays: short streaks
        streak = np.zeros((h, w), np.float32)
        n = int(rng.uniform(10, 60))
        idx = rng.integers(0, [h, w], size=(n, 2))
        streak[idx[:, 0], idx[:, 1]] = 1
        ang = rng.uniform(0, 180)
        k = np.zeros((15, 15), np.float32)
        k[7, :] = 1
        k = ndimage.rotate(k, ang, reshape=False, order=1)
        streak = ndimage.convolve(streak, k / k.sum())
        a = a * (1 + rng.uniform(-0.3, 0.3) * np.clip(streak * 8, 0, 1))[..., None]
    if rng.uniform() < 0.5:
        a = ndimage.gaussian_filter(a, (rng.uniform(0.3, 1.5),) * 2 + (0,))
    a = a + rng.uniform(0, 0.03) * rng.standard_normal(a.shape).astype(np.float32)
    out = np.clip(a * 255, 0, 255).astype(np.uint8)
    if rng.uniform() < 0.5:
        buf = io.BytesIO()
        Image.fromarray(out).save(buf, format="JPEG", quality=int(rng.integers(40, 95)))
        out = np.asarray(Image.open(buf).convert("RGB"))
    return out


def augment_photo(photo: np.ndarray, rng: np.random.Generator) -> np.ndarray:
    """Photo-style augmentation (module docstring) of an ``(h, w, 3)`` uint8 face photo."""
    return _augment(photo, rng)


def net_input(photo: np.ndarray) -> np.ndarray:
    """``(h, w)`` float32: what the net sees of a photo (flattened, contrast-normalised luminance)."""
    from .rings import _normalise, luminance

    lum = luminance(photo)
    return _normalise(lum, sigma=0.5 * max(lum.shape)).astype(np.float32)


@restores_torch_threads
def train_ring_net(spec: RingNetSpec, x: np.ndarray, y: np.ndarray, out_dir, *, progress: bool = True,
                   member: str = "main") -> dict:
    """Train the ring net of ``spec`` from scratch on inputs ``x (n, h, w)`` (:func:`net_input`)
    and targets ``y (n, h, w)`` in [0, 1] (made by :func:`woodcam.synth.ring_training_faces`);
    write ``rings_spec.json``, ``rings.pt`` and ``rings_train_log.csv`` to ``out_dir``
    (``member="quilted"``: ``rings_quilted_*``, :func:`member_files`; ``spec`` of a quilted style).
    The log has a row every ``spec.log_every`` steps and one for the last step (its ``step`` is
    0-based: ``step + 1`` steps made the weights, fewer than ``spec.steps`` after a
    ``max_train_s`` stop). Returns ``{"steps", "train_s", "final_loss", "params"}``."""
    torch = require("torch", "learn", "training the ring net")
    from .._progress import progress_bar

    check_member(spec, member)
    check_trainable(spec, x.shape[1:])
    spec_name, weights_name, log_name = member_files(member)

    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    torch.set_num_threads(1)           # the machine is shared; one thread also keeps runs repeatable
    rng = np.random.default_rng([spec.seed, 1])
    # the spec's seed draws the initial weights on a fork of torch's generator (as build_model):
    # seeded globally, each training run reset the caller's torch random numbers to the seed's
    # stream. The same draws, so the same weights; the loop takes nothing from torch's generator
    # (the batches, crops and turns come from rng)
    with torch.random.fork_rng(devices=[]):
        torch.manual_seed(spec.seed)
        net = _net(spec)
    n_params = sum(p.numel() for p in net.parameters())
    opt = torch.optim.Adam(net.parameters(), lr=spec.lr)
    sched = torch.optim.lr_scheduler.CosineAnnealingLR(opt, spec.steps, eta_min=spec.lr * 0.05)
    pos_weight = torch.tensor(float((1 - y.mean()) / max(y.mean(), 1e-6)) ** 0.5)
    loss_fn = torch.nn.BCEWithLogitsLoss(pos_weight=pos_weight)
    n, h, w = x.shape
    c = spec.crop_px
    t0 = time.perf_counter()
    rows, loss_avg, step = [], None, 0
    bar = progress_bar(range(spec.steps), desc="training ring net", unit="step", enabled=progress)
    for step in bar:
        idx = rng.integers(0, n, spec.batch)
        r0 = rng.integers(0, h - c + 1, spec.batch)
        c0 = rng.integers(0, w - c + 1, spec.batch)
        xb = np.stack([x[i, a:a + c, b:b + c] for i, a, b in zip(idx, r0, c0)])
        yb = np.stack([y[i, a:a + c, b:b + c] for i, a, b in zip(idx, r0, c0)])
        flip = rng.integers(0, 4)
        xb, yb = np.rot90(xb, flip, axes=(1, 2)), np.rot90(yb, flip, axes=(1, 2))
        xt = torch.from_numpy(np.ascontiguousarray(xb)[:, None])
        yt = torch.from_numpy(np.ascontiguousarray(yb)[:, None])
        loss = loss_fn(net(xt), yt)
        opt.zero_grad()
        loss.backward()
        opt.step()
        sched.step()
        v = float(loss.detach())
        loss_avg = v if loss_avg is None else 0.98 * loss_avg + 0.02 * v
        if step % spec.log_every == 0:
            rows.append({"step": step, "loss": v, "loss_avg": loss_avg, "seconds": time.perf_counter() - t0})
            bar.set_postfix(loss=f"{loss_avg:.4f}", refresh=False)
        if time.perf_counter() - t0 > spec.max_train_s:
            break
    train_s = time.perf_counter() - t0
    if rows and rows[-1]["step"] != step:
        # the last step always: the log is the one record of how many steps made the weights (a
        # max_train_s stop ends anywhere; the committed net's log ended at 2550 of its 2593)
        rows.append({"step": step, "loss": v, "loss_avg": loss_avg, "seconds": train_s})
    spec.save(out / spec_name)
    with atomic_path(out / weights_name) as tmp:
        torch.save({k: v.detach().clone() for k, v in net.state_dict().items()}, tmp)
    with atomic_write(out / log_name, "w", newline="") as fh:
        wr = csv.DictWriter(fh, ["step", "loss", "loss_avg", "seconds"])
        wr.writeheader()
        wr.writerows(rows)
    return {"steps": step + 1, "train_s": train_s, "final_loss": loss_avg, "params": n_params}


# -- inference ---------------------------------------------------------------------------------------

_CACHE: dict = {}


def load_ring_net(models_dir=MODELS_DIR, member: str = "main"):
    """The trained net (eval mode) ``member`` (:data:`RING_NET_MEMBERS`) of ``models_dir``;
    cached per folder and member, read again when its spec or weights file changed."""
    return _load_ring_net(models_dir, member, str(Path(models_dir).resolve()))


def _load_ring_net(models_dir, member: str, folder_key: str):
    """:func:`load_ring_net` with the folder's resolved path ``folder_key`` (the cache key) read by
    the caller: :func:`ring_probability` resolves its folder once for all its members."""
    require("torch", "learn", "the learned ring detector")
    spec_name, weights_name, _ = member_files(member)
    key = (folder_key, member)
    # the files' identity is part of the entry: weights retrained or restored into the folder
    # (train_ring_net, a copy) were never read again in this process, the old net answered
    stamp = _files_stamp(Path(models_dir), (spec_name, weights_name))
    if key not in _CACHE or _CACHE[key][0] != stamp:
        _CACHE.pop(key, None)
        path = Path(models_dir) / weights_name
        if member == "main" and not path.is_file():
            raise WoodcamError(f"no trained ring net at {str(path)!r}; train one with "
                               f"'woodcam train rings --out {models_dir}'")
        try:
            spec = RingNetSpec.load(Path(models_dir) / spec_name)
            if member != "main" and spec.style not in QUILTED_STYLES:
                raise WoodcamError(f"its spec has style {spec.style!r}, "
                                   f"not a quilted one ({', '.join(QUILTED_STYLES)})")
            net = _net(spec)
            net.load_state_dict(torch_state(path, net.state_dict(), "the learned ring detector"))
        except Exception as e:
            fix = (f"retrain it with 'woodcam train rings --member {member} --spec SPEC --out {models_dir}' "
                   f"or remove {spec_name} and {weights_name}" if member != "main" else
                   f"restore {spec_name} and {weights_name} (the packaged net: reinstall woodcam or check out "
                   f"woodcam/models) or retrain them with 'woodcam train rings --spec SPEC --out {models_dir}'")
            if member == "main" and isinstance(e, WoodcamError):    # the spec's own words, and the fix
                raise WoodcamError(f"{e}; {fix}") from e
            why = (str(e).strip().splitlines() or [type(e).__name__])[0]  # one line, never torch's per-tensor list
            raise WoodcamError(f"ring net {member!r} in {str(models_dir)!r} ({weights_name} with {spec_name}) cannot "
                               f"be loaded: {why}; {fix}") from e
        net.eval()
        _CACHE[key] = (stamp, net)
    return _CACHE[key][1]


def _files_stamp(folder: Path, names) -> tuple:
    """``(inode, size, mtime ns)`` of each file (None where it cannot be read): changes when a
    file is rewritten (written atomically: a new inode) or replaced."""
    out = []
    for name in names:
        try:
            st = (folder / name).stat()
        except OSError:
            out.append(None)
        else:
            out.append((st.st_ino, st.st_size, st.st_mtime_ns))
    return tuple(out)


def ring_members(models_dir=MODELS_DIR) -> list[tuple[str, float]]:
    """The members of ``models_dir`` and their weights in :func:`ring_probability`:
    ``[("main", 1.0)]``, or with a quilted member (either of its files present; a half-present
    member is refused when loaded) ``[("main", 1 - w), ("quilted", w)]``, ``w`` =
    :data:`QUILTED_MEMBER_WEIGHT`."""
    folder = Path(models_dir)
    if any((folder / n).exists() for n in member_files("quilted")[:2]):
        return [("main", 1.0 - QUILTED_MEMBER_WEIGHT), ("quilted", QUILTED_MEMBER_WEIGHT)]
    return [("main", 1.0)]


def ring_probability(photo: np.ndarray, models_dir=MODELS_DIR) -> np.ndarray:
    """``(h, w)`` float32 in [0, 1]: the net's ring-line probability on a face photo (with a
    quilted member, the weighted mean of the members' probabilities, :func:`ring_members`)."""
    torch = require("torch", "learn", "the learned ring detector")
    x = net_input(photo)
    h, w = x.shape
    ph, pw = (-h) % 4, (-w) % 4
    x = np.pad(x, ((0, ph), (0, pw)), mode="reflect")
    folder_key = str(Path(models_dir).resolve())  # once per face, not once per member
    members = [(_load_ring_net(models_dir, m, folder_key), wt) for m, wt in ring_members(models_dir)]
    # one thread: the net is small, and on a 256 px face torch's two threads spent 0.69 CPU-s
    # where one spends 0.15 (the budget is 1 CPU-s per face for the whole detector)
    from .._threads import torch_threads

    with torch_threads(torch, 1), torch.no_grad():
        xt = torch.from_numpy(x)[None, None]
        p = sum(wt * torch.sigmoid(net(xt))[0, 0].numpy().astype(np.float64) for net, wt in members)
    return np.clip(p[:h, :w], 0.0, 1.0).astype(np.float32)


#: How the learned detector places its ring lines (:func:`detect_rings_learned`).
LearnedMode = Literal["snap", "ridge"]
LEARNED_MODES: tuple[str, ...] = get_args(LearnedMode)
#: Net probability below which a snapped line is dropped (``"snap"``): the net sees no ring
#: boundary within reach of the classical line.
SNAP_MIN_PROBABILITY = 0.2


def _snap_to_net(p: np.ndarray, base, min_p: float = SNAP_MIN_PROBABILITY):
    """``"snap"``: the classical detector's ring pieces (``base``, a RingDetection) moved across
    the ring onto the net's ridge (the maximum of ``p (h, w)`` within
    :data:`~woodcam.detect.rings.SNAP_REACH_WAVELENGTHS` of a spacing, profiles averaged along
    the ring, median-filtered along each piece, cut where the line jumps; the classical
    ``_snap`` with the net's probability in place of the darkness), keeping each piece's ring id
    and order; stretches whose ridge probability is below ``min_p`` are dropped. Returns
    ``(traces, ring_order)``."""
    from .rings import MIN_TRACE_WAVELENGTHS, RingTrace, _sample, _snap

    polys = [t.points_px for t in base.traces]
    if not polys:
        return [], []
    moved, src = _snap(-p, polys, base.normal_rad, base.wavelength_px, "dark-line")
    traces, order = [], []
    for q, k in zip(moved, src):
        on = _sample(p, q) >= min_p
        cuts = np.flatnonzero(np.diff(on.astype(np.int8))) + 1
        for piece, keep in zip(np.split(q, cuts), np.split(on, cuts)):
            lam = float(np.median(_sample(base.wavelength_px, piece)))
            if keep[0] and len(piece) >= 3 and (np.sum(np.hypot(*np.diff(piece, axis=0).T))
                                                >= MIN_TRACE_WAVELENGTHS * lam):
                traces.append(RingTrace(piece, ring=base.traces[k].ring))
                order.append(base.ring_order[k] if k < len(base.ring_order) else 0.0)
    return traces, order


def detect_rings_learned(photo: np.ndarray, *, px_per_mm: float | None = None, name: str = "face",
                         models_dir=MODELS_DIR, mode: LearnedMode = "snap"):
    """Rings on one face photo by the learned net (module docstring); a RingDetection.

    ``mode``: ``"snap"`` (default), the classical detector's ring pieces (their ring ids and
    order) moved onto the net's ridge and dropped where the net sees none (:func:`_snap_to_net`);
    ``"ridge"``, the net's own ridges across the classical ring normal (no ring ids)."""
    from scipy import ndimage

    from .rings import (
        MIN_RING_AREA,
        RING_MAP_SIGMA_MM,
        RingDetection,
        RingTrace,
        _contour_runs,
        detect_rings,
        ring_map_from_traces,
    )

    if mode not in LEARNED_MODES:
        raise WoodcamError(f"mode must be one of {', '.join(LEARNED_MODES)}; got {mode!r}")
    base = detect_rings(photo, px_per_mm=px_per_mm, name=name)      # orientation and spacing
    p = ring_probability(photo, models_dir)
    h, w = p.shape
    warnings = []
    sigma_px = RING_MAP_SIGMA_MM * (px_per_mm if px_per_mm else 256 / 50.0)
    if mode == "snap":
        traces, order = _snap_to_net(p, base)
        return RingDetection(traces, ring_map_from_traces(traces, (h, w), sigma_px), base.normal_rad,
                             base.wavelength_px, base.confidence, base.evidence, "learned",
                             list(base.warnings), base.order_map, order)
    pr = ndimage.gaussian_filter(p, 1.0, order=(1, 0))
    pc = ndimage.gaussian_filter(p, 1.0, order=(0, 1))
    sn, cn = np.sin(base.normal_rad), np.cos(base.normal_rad)
    dn = pr * sn + pc * cn                                              # slope across the rings
    # curvature across the rings: the ridge is where the slope is 0 and the curvature negative
    # (a maximum of p; the slope is 0 in the valleys between rings too)
    d2 = (ndimage.gaussian_filter(p, 1.0, order=(2, 0)) * sn * sn
          + 2 * ndimage.gaussian_filter(p, 1.0, order=(1, 1)) * sn * cn
          + ndimage.gaussian_filter(p, 1.0, order=(0, 2)) * cn * cn)
    keep = (ndimage.gaussian_filter(p, 1.0) >= 0.35) & (d2 < 0)
    polys = _contour_runs(dn, keep, 0.5 * base.wavelength_px)
    traces = [RingTrace(q) for q in polys]
    if float((p > 0.35).mean()) < 0.02 * MIN_RING_AREA or not traces:
        warnings.append(f"face {name!r}: the learned detector found no rings; check the photo")
    return RingDetection(traces, ring_map_from_traces(traces, (h, w), sigma_px), base.normal_rad,
                         base.wavelength_px, p, p > 0.35, "learned", warnings)
