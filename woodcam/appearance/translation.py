"""Per-axis image translation from ring images to face photos (seed 000, section 3.3.1).

For each block axis a small fully convolutional network learns to turn an image of the rings
(the ARF of eq. 6, or a Mokume-style ring map) into the photograph of a face normal to that
axis. It is trained from scratch on patches cropped at the same place from the input and the
photo of the faces of that axis (both faces when both have photos), with losses that need no
pretrained network: L1 on the colours plus a texture-statistics term that matches, per patch and
colour channel, the mean and the standard deviation of the high-pass image (the fine grain a
pure L1 loss averages away). The seed uses Texler et al.'s patch-trained U-Net/ResNet generator
(~15 min per network on a GPU); this one is a two-level U-Net with 16-32 channels, sized to
train in seconds on two CPU cores.

Data forms
----------
- input images: ``(c, h, w)`` float32; channel 0 the ring image (ARF in [0, 1) or ring map in
  [0, 1]); channel 1, when ``spec.noise``, a solid value noise sampled at the pixels' block
  points, so texture the rings do not explain can still vary (and stays continuous through
  a volume, because the noise is a function of 3D position).
- target images: ``(h, w, 3)`` float32 sRGB in [0, 1] (photos / 255).
- weights are trained per block at run time; nothing is downloaded.
"""

from __future__ import annotations

import time
from dataclasses import asdict, dataclass, replace
from typing import Literal, get_args

import numpy as np

from .._readers import check_state_shapes
from .._threads import restores_torch_threads
from ..errors import WoodcamError, require

Quality = Literal["draft", "normal", "high"]
QUALITIES: tuple[str, ...] = get_args(Quality)


@dataclass(frozen=True)
class TranslationSpec:
    """Size and training schedule of one translation network (an experiment spec).

    Attributes
    ----------
    channels : int
        Feature channels at full resolution (twice as many at half resolution).
    patch_px : int
        Side of the square training patches, pixels of the training images (even).
    patches : int
        Size of the patch pool cropped once per training run (the seed's N_p = 2000).
    epochs : int
        Passes over the pool (the seed trains 300 epochs).
    batch : int
        Patches per optimisation step.
    lr : float
        Adam learning rate (decayed by cosine to 5 % over the run).
    texture_weight : float
        Weight of the high-pass statistics term against L1.
    noise : bool
        Add the solid-noise input channel.
    noise_mm : float
        Lattice cell of the solid noise (mm).
    augment : bool
        Train on randomly mirrored patches too (left-right and up-down, each with probability
        1/2, input and photo together): mirrored wood is still plausible wood on side and end
        grain alike, and a network that learns one or two photos then memorises less of their
        layout.
    finetune_epochs : int
        Per-axis networks start from a network trained on all faces and are fine-tuned for
        this many epochs on their axis's faces (more data than one axis's one or two photos,
        while keeping each axis's look); 0 trains each axis from scratch, as the seed does.
    seed : int
        Seeds torch and the patch sampler: the same spec and data give the same network.
    """

    channels: int = 16
    patch_px: int = 32
    patches: int = 512
    epochs: int = 4
    batch: int = 16
    lr: float = 4e-3
    texture_weight: float = 1.0
    noise: bool = True
    noise_mm: float = 0.6
    augment: bool = False
    finetune_epochs: int = 2
    seed: int = 0

    @property
    def steps(self) -> int:
        """Optimisation steps: ``epochs * ceil(patches / batch)``."""
        return self.epochs * -(-self.patches // self.batch)

    def to_dict(self) -> dict:
        return asdict(self)


#: Presets for ``--quality``; ``--epochs`` overrides the preset's epochs.
QUALITY_SPECS: dict[str, TranslationSpec] = {
    "draft": TranslationSpec(channels=12, patch_px=32, patches=256, epochs=3),
    "normal": TranslationSpec(),
    "high": TranslationSpec(channels=24, patch_px=48, patches=1024, epochs=8),
}


def translation_spec(quality: Quality = "normal", epochs: int | None = None, seed: int = 0,
                     **changes) -> TranslationSpec:
    """The spec of a ``quality`` preset with ``epochs`` and other fields overridden."""
    if quality not in QUALITY_SPECS:
        raise WoodcamError(f"quality must be one of {', '.join(QUALITIES)}; got {quality!r}")
    spec = QUALITY_SPECS[quality]
    if epochs is not None:
        if int(epochs) < 1:
            raise WoodcamError(f"epochs must be >= 1; got {epochs!r}")
        changes["epochs"] = int(epochs)
    return replace(spec, seed=int(seed), **changes)


def _build_net(c_in: int, ch: int):
    """Two-level U-Net: 3x3 convs, one stride-2 level with a skip, sigmoid RGB out."""
    torch = require("torch", "learn", "the neural wood appearance")
    nn = torch.nn

    def conv(a, b, stride=1, dilation=1):
        return nn.Conv2d(a, b, 3, stride=stride, padding=dilation, dilation=dilation,
                         padding_mode="reflect")

    class _UNet(nn.Module):
        def __init__(self):
            super().__init__()
            act = nn.LeakyReLU(0.2)
            self.enc = nn.Sequential(conv(c_in, ch), act, conv(ch, ch), act)
            self.down = nn.Sequential(conv(ch, 2 * ch, stride=2), act, conv(2 * ch, 2 * ch, dilation=2), act)
            self.up = nn.Sequential(nn.Upsample(scale_factor=2, mode="bilinear", align_corners=False),
                                    conv(2 * ch, ch), act)
            self.dec = nn.Sequential(conv(2 * ch, ch), act, nn.Conv2d(ch, 3, 1))

        def forward(self, x):
            e = self.enc(x)
            u = self.up(self.down(e))
            return torch.sigmoid(self.dec(torch.cat([e, u], dim=1)))

    return _UNet()


def _highpass_stats(x):
    """Per patch and channel: mean and std of ``x - box3x3(x)``, shape ``(b, 2c)``."""
    torch = require("torch", "learn", "the neural wood appearance")
    hp = x - torch.nn.functional.avg_pool2d(x, 3, stride=1, padding=1, count_include_pad=False)
    hp = hp[..., 1:-1, 1:-1]
    return torch.cat([hp.abs().mean(dim=(2, 3)), hp.std(dim=(2, 3))], dim=1)


class TranslationNet:
    """A trained translation network: ``net(inputs (c, h, w)) -> rgb (h, w, 3)``.

    Attributes
    ----------
    spec : TranslationSpec
    c_in : int
        Input channels.
    module : torch.nn.Module
    train_seconds : float
    final_l1 : float
        Mean L1 colour error over the last tenth of the training steps.
    """

    def __init__(self, module, spec: TranslationSpec, c_in: int, train_seconds: float = 0.0,
                 final_l1: float = float("nan")):
        self.module, self.spec, self.c_in = module, spec, c_in
        self.train_seconds, self.final_l1 = train_seconds, final_l1

    def __call__(self, inputs: np.ndarray, batch_pixels: int = 1 << 19) -> np.ndarray:
        """Translate ``(c, h, w)`` or ``(n, c, h, w)`` inputs to ``(h, w, 3)`` / ``(n, h, w, 3)``
        float32 RGB in [0, 1]; images of any size (odd sizes are padded by reflection)."""
        torch = require("torch", "learn", "the neural wood appearance")
        x = np.asarray(inputs, np.float32)
        single = x.ndim == 3
        x = x[None] if single else x
        if x.ndim != 4 or x.shape[1] != self.c_in:
            raise WoodcamError(f"inputs must have shape (n, {self.c_in}, h, w); got {np.shape(inputs)}")
        n, _, h, w = x.shape
        ph, pw = h % 2, w % 2
        out = np.empty((n, h, w, 3), np.float32)
        step = max(1, batch_pixels // (h * w))
        self.module.eval()
        with torch.no_grad():
            for i in range(0, n, step):
                t = torch.from_numpy(x[i:i + step])
                if ph or pw:
                    t = torch.nn.functional.pad(t, (0, pw, 0, ph), mode="replicate")
                y = self.module(t)[:, :, :h, :w]
                out[i:i + step] = y.permute(0, 2, 3, 1).numpy()
        return out[0] if single else out

    def state(self) -> dict:
        """Everything needed to rebuild the network (weights as numpy arrays)."""
        sd = {k: v.detach().cpu().numpy() for k, v in self.module.state_dict().items()}
        return {"spec": self.spec.to_dict(), "c_in": self.c_in, "weights": sd,
                "train_seconds": self.train_seconds, "final_l1": self.final_l1}

    @classmethod
    def from_state(cls, state: dict) -> "TranslationNet":
        torch = require("torch", "learn", "the neural wood appearance")
        spec = TranslationSpec(**state["spec"])
        module = _build_net(int(state["c_in"]), spec.channels)
        weights = {k: torch.from_numpy(np.asarray(v)) for k, v in state["weights"].items()}
        check_state_shapes(module.state_dict(), weights)  # one ValueError line, not torch's per-tensor list
        module.load_state_dict(weights)
        return cls(module, spec, int(state["c_in"]), float(state.get("train_seconds", 0.0)),
                   float(state.get("final_l1", float("nan"))))


def _crop_pool(pairs, spec: TranslationSpec, rng: np.random.Generator):
    """Crop ``spec.patches`` aligned patches from the pairs, area-weighted over images."""
    p = spec.patch_px
    usable = [(x, y, m) for x, y, m in pairs if x.shape[1] >= p and x.shape[2] >= p]
    if not usable:
        shapes = [x.shape[1:] for x, _, _ in pairs]
        # patch_px is no option of any command: name the grid resolution, which sets the sizes
        raise WoodcamError(
            f"the appearance networks learn from face images at least {p} cells on each side; the "
            f"colour-volume grid gives {', '.join('x'.join(map(str, s)) for s in shapes)} cells; raise "
            "its resolution (--resolution, cells along the block's longest side)"
        )
    areas = np.array([x.shape[1] * x.shape[2] for x, _, _ in usable], float)
    which = rng.choice(len(usable), size=spec.patches, p=areas / areas.sum())
    xs, ys, ms = [], [], []
    for k in range(len(usable)):
        idx = np.flatnonzero(which == k)
        if not len(idx):
            continue
        x, y, m = usable[k]
        r = rng.integers(0, x.shape[1] - p + 1, len(idx))
        c = rng.integers(0, x.shape[2] - p + 1, len(idx))
        # Fancy indexing of all patch windows at once (no per-patch loop).
        rr = r[:, None, None] + np.arange(p)[None, :, None]
        cc = c[:, None, None] + np.arange(p)[None, None, :]
        xs.append(np.moveaxis(x[:, rr, cc], 0, 1))          # (k, c, p, p)
        ys.append(np.moveaxis(y[rr, cc], 3, 1))             # (k, 3, p, p)
        ms.append(m[rr, cc][:, None])                       # (k, 1, p, p)
    return (np.concatenate(xs).astype(np.float32), np.concatenate(ys).astype(np.float32),
            np.concatenate(ms).astype(np.float32))


def _mirror(torch, rng: np.random.Generator, *batch):
    """The same random left-right / up-down mirroring of each patch of every tensor
    ``(b, c, p, p)`` in ``batch`` (a patch and its photo stay aligned)."""
    b = batch[0].shape[0]
    flips = rng.random((2, b)) < 0.5
    out = []
    for t in batch:
        for dim, f in ((3, flips[0]), (2, flips[1])):
            sel = torch.from_numpy(f).view(b, 1, 1, 1)
            t = torch.where(sel, t.flip(dim), t)
        out.append(t)
    return out


@restores_torch_threads
def train_translation(pairs, spec: TranslationSpec | None = None, *, progress: bool = True,
                      desc: str = "translation", threads: int | None = 1,
                      init: TranslationNet | None = None) -> TranslationNet:
    """Train one translation network from scratch on aligned image pairs.

    Parameters
    ----------
    pairs : list of (inputs (c, h, w) float, photo (h, w, 3) float in [0, 1], mask (h, w) bool)
        Images of the faces of one axis; ``mask`` marks the pixels to learn from.
    spec : TranslationSpec, default the "normal" preset.
    progress : bool
        Show a tqdm bar over the optimisation steps.
    init : TranslationNet, optional
        Start from a copy of this network's weights and train ``spec.finetune_epochs`` epochs.
    threads : int or None
        ``torch.set_num_threads`` for the run (None leaves torch's setting). Default 1: these
        convolutions are too small to split, and on a busy 2-core machine torch's OpenMP
        threads spin against each other (measured 1.7 s a step with 2 threads against 0.14 s
        with 1 at load 7.5).

    Returns
    -------
    TranslationNet
    """
    torch = require("torch", "learn", "the neural wood appearance")
    spec = spec or QUALITY_SPECS["normal"]
    if spec.patch_px % 2:
        raise WoodcamError(f"patch_px must be even (one stride-2 level); got {spec.patch_px}")
    if not pairs:
        raise WoodcamError("pairs must hold at least one (inputs, photo, mask) image pair; got none")
    c_in = int(np.asarray(pairs[0][0]).shape[0])
    # Images smaller than the patch (thin blocks at low resolution) shrink the patch to the
    # largest even size that fits the biggest image, never below 8 px.
    fit = max(min(np.asarray(x).shape[1:]) for x, _, _ in pairs) // 2 * 2
    if fit < spec.patch_px:
        spec = replace(spec, patch_px=max(8, fit))
    if threads:
        torch.set_num_threads(int(threads))
    t0 = time.perf_counter()
    rng = np.random.default_rng(spec.seed)
    X, Y, M = (torch.from_numpy(a) for a in _crop_pool(pairs, spec, rng))
    # the spec's seed draws the initial weights on a fork of torch's generator: seeded globally,
    # each run (each axis of a bake's appearance) reset the caller's torch random numbers. The
    # same draws, so the same weights; the loop takes nothing from torch's generator (rng mirrors)
    with torch.random.fork_rng(devices=[]):
        torch.manual_seed(spec.seed)
        net = _build_net(c_in, spec.channels)
    if init is not None:
        net.load_state_dict(init.module.state_dict())
        spec = replace(spec, epochs=max(1, spec.finetune_epochs))
    opt = torch.optim.Adam(net.parameters(), lr=spec.lr)
    sched = torch.optim.lr_scheduler.CosineAnnealingLR(opt, spec.steps, eta_min=0.05 * spec.lr)
    order = torch.from_numpy(rng.permutation(np.resize(np.arange(len(X)), spec.steps * spec.batch)))
    from .._progress import progress_bar

    bar = progress_bar(range(spec.steps), desc=desc, unit="step", enabled=progress, leave=False)
    tail = []
    net.train()
    for s in bar:
        idx = order[s * spec.batch:(s + 1) * spec.batch]
        x, y, m = X[idx], Y[idx], M[idx]
        if spec.augment:
            x, y, m = _mirror(torch, rng, x, y, m)
        out = net(x)
        l1 = ((out - y).abs() * m).sum() / (3 * m.sum()).clamp(min=1)
        loss = l1
        if spec.texture_weight > 0:
            loss = loss + spec.texture_weight * (_highpass_stats(out) - _highpass_stats(y)).abs().mean()
        opt.zero_grad()
        loss.backward()
        opt.step()
        sched.step()
        if s >= spec.steps - max(1, spec.steps // 10):
            tail.append(float(l1.detach()))
        if progress and s % 20 == 0:
            bar.set_postfix(l1=f"{float(l1.detach()):.3f}", refresh=False)
    return TranslationNet(net, spec, c_in, time.perf_counter() - t0, float(np.mean(tail)))
