"""The neural appearance: colour volumes learnt from the block's own photos (seed 000, 3.3).

:func:`fit_neural_appearance` trains one translation network per block axis on that axis's face
photos (:mod:`.translation`), runs it over the axis-aligned slices of the field's ARF volume
(:mod:`.volumes`) and caches the three uint8 volumes (and the weights) on disk, keyed by the
block's images, the field and the settings. :class:`NeuralAppearance` answers
``color(field, points_mm, normals)`` by trilinear lookup in the volumes blended by eq. 10 (or
from one volume for every normal: the orientation-agnostic variant of the seed's Fig. 13).
:func:`block_appearance` picks colour map or neural for a block and falls back to the colour map,
with a :class:`AppearanceFallbackWarning`, when the block has no photos to learn from.
"""

from __future__ import annotations

import json
import time
import warnings
from dataclasses import dataclass
from pathlib import Path
from typing import Literal, get_args

import numpy as np

from .._checks import received
from ..errors import WoodcamError, WoodcamWarning
from ..fields.base import check_points, evaluate
from ..frames import FACE_AXIS
from .colormap import ColorMapAppearance
from .orientation import axis_weights
from .translation import Quality, TranslationNet, train_translation, translation_spec
from .volumes import (PLANE_AXES, ColorVolumes, VolumeGrid, cache_key, face_pair, guide_slopes,
                      point_guide, translate_volume, years_volume)
from .._types import AppearanceLike, GrowthFieldLike, PathLike
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from ..block import Block

Orientation = Literal["dependent", "agnostic"]
Source = Literal["auto", "arf", "ring_map"]
AppearanceKind = Literal["colormap", "neural"]
APPEARANCE_KINDS: tuple[str, ...] = get_args(AppearanceKind)

#: Bumped when the network, its inputs or the volume layout change, so old caches are not reused.
CACHE_VERSION = 2

_AXIS_NAMES = ("x", "y", "z")


class NoPhotosError(WoodcamError):
    """The block has no face photos to learn an appearance from."""


class AppearanceFallbackWarning(WoodcamWarning):
    """The neural appearance was asked for but the colour map is used instead (reason given)."""


def default_cache_dir() -> Path:
    """``$WOODCAM_CACHE_DIR/appearance`` or the user cache folder's ``appearance`` (platformdirs,
    honouring ``$XDG_CACHE_HOME``): see :mod:`woodcam._cache`."""
    from .._cache import cache_dir

    return cache_dir("appearance")


@dataclass
class NeuralAppearance:
    """Colour from per-axis colour volumes (see module docstring).

    Attributes
    ----------
    volumes : ColorVolumes
        Three volumes (blended by eq. 10 over the surface normal) or one (used for all normals).
    """

    volumes: ColorVolumes

    @property
    def orientation(self) -> Orientation:
        return "dependent" if len(self.volumes.volumes) == 3 else "agnostic"

    @property
    def meta(self) -> dict:
        return self.volumes.meta

    def color(self, field, points_mm, normals) -> np.ndarray:
        """Colour ``(n, 3)`` float32 in [0, 1] at ``points_mm (n, 3)`` with ``normals (n, 3)``.

        The volumes hold the colour per cell; when they carry sub-cell detail and ``field`` is
        given (it must be the field they were built from, as in a :class:`~.wood.Wood`), the
        field's rings at the points themselves add the detail inside the cells
        (:meth:`ColorVolumes.sample`). ``field=None`` gives the plain trilinear colour.
        """
        p = check_points(points_mm)
        vols = self.volumes
        detail = field is not None and vols.has_detail
        source = vols.meta.get("settings", {}).get("source", "arf")
        years = evaluate(field, p) if detail else None

        def guide(k, idx=None):
            if not detail:
                return None
            axis = 2 if len(vols.volumes) == 1 else k
            cell = float(vols.grid.cell_mm[list(PLANE_AXES[axis])].mean())
            q, y = (p, years) if idx is None else (p[idx], years[idx])
            return point_guide(field, q, axis, source, cell, years=y)

        if len(vols.volumes) == 1:
            return vols.sample(p, 0, guide(0))
        # Eq. 10, looking up each volume only where its weight is non-zero (flat CAD faces are
        # mostly axis-aligned, so this skips two of the three lookups there).
        w = axis_weights(normals)
        out = np.zeros((len(p), 3), np.float32)
        for k in range(3):
            idx = np.flatnonzero(w[:, k] > 0)
            if len(idx) == len(p):
                out += w[:, k:k + 1] * vols.sample(p, k, guide(k))
            elif len(idx):
                out[idx] += w[idx, k:k + 1] * vols.sample(p[idx], k, guide(k, idx))
        return out

    def agnostic(self, index: int = 2) -> NeuralAppearance:
        """The same block seen through one volume for every normal (default ``RGB_XY``)."""
        v = self.volumes
        cut = slice(index, index + 1)
        return NeuralAppearance(ColorVolumes(v.grid, v.volumes[cut], dict(v.meta, orientation="agnostic"),
                                             None if v.guides is None else v.guides[cut],
                                             None if v.slopes is None else v.slopes[cut]))


def photo_faces(block) -> list[str]:
    """Names of the block's faces that have a photo."""
    return [n for n, f in block.faces.items() if f.photo is not None]


def train_axis_networks(block, grid: VolumeGrid, spec, *, field=None, source: str = "arf",
                        orientation: Orientation = "dependent", faces=None, progress: bool = True,
                        threads: int | None = 1) -> dict:
    """Train the translation networks of a block.

    Parameters
    ----------
    faces : face names to learn from (default: every face with a photo).
    orientation : "dependent" trains one network per axis on the faces of that axis (with
        ``spec.finetune_epochs > 0`` by fine-tuning the network trained on all faces; an axis
        whose faces have no photo gets the network trained on all faces, noted in the result);
        "agnostic" trains one network on all faces.

    Returns
    -------
    dict with ``"nets"``: list of 3 (or 1) :class:`TranslationNet` and ``"notes"``: list of str.
    """
    faces = [f for f in (faces or photo_faces(block)) if block.faces[f].photo is not None]
    if not faces:
        raise NoPhotosError(
            f"block {block.name!r} has no face photos to train the neural appearance on; "
            "add photos or use the colour map (appearance='colormap')"
        )
    pairs = {f: face_pair(block, f, grid, spec, field=field, source=source) for f in faces}
    notes = []
    pooled = None

    def pooled_net():
        nonlocal pooled
        if pooled is None:
            pooled = train_translation(list(pairs.values()), spec, progress=progress,
                                       desc="appearance: all faces", threads=threads)
        return pooled

    if orientation == "agnostic":
        return {"nets": [pooled_net()], "notes": notes}
    if orientation != "dependent":
        raise WoodcamError(f"orientation must be 'dependent' or 'agnostic'; got {orientation!r}")
    nets = []
    for k in range(3):
        mine = [pairs[f] for f in faces if FACE_AXIS[f] == k]
        if mine:
            init = pooled_net() if spec.finetune_epochs > 0 else None
            nets.append(train_translation(mine, spec, progress=progress, threads=threads, init=init,
                                          desc=f"appearance: {_AXIS_NAMES[k]} faces"))
        else:
            notes.append(f"no photo of a face normal to {_AXIS_NAMES[k].upper()}: "
                         "that axis uses the network trained on all faces")
            nets.append(pooled_net())
    return {"nets": nets, "notes": notes}


def fit_neural_appearance(block: Block, field: GrowthFieldLike | None = None, *,
                          resolution: int = 128, quality: Quality = "normal",
                          epochs: int | None = None, seed: int = 0,
                          orientation: Orientation = "dependent", source: Source = "auto",
                          cache_dir: PathLike | Literal[False] | None = None, progress: bool = True,
                          threads: int | None = 1, detail: bool = True) -> NeuralAppearance:
    """Learn a block's appearance from its photos and build its colour volumes (cached).

    Parameters
    ----------
    block : woodcam.block.Block
        Needs at least one face photo (else :class:`NoPhotosError`).
    field : growth field, default ``block.true_field``
        Any callable ``(n, 3) mm -> years``; its ARF (eq. 6) is the networks' input, on the faces
        for training and through the volume for the colour volumes.
    resolution : int
        Volume cells along the longest block side (default 128, at most 256).
    quality, epochs, seed : the translation spec (:func:`~.translation.translation_spec`).
    orientation : "dependent" (three volumes, eq. 10) or "agnostic" (one volume from a network
        trained on all faces).
    source : "arf" (the seed's choice: networks translate the ARF, on faces and in the volume)
        or "ring_map": networks learn (face ring map -> photo) and run on ring-map-like slices of
        the field (:func:`~.volumes.ring_map_like`). Use it for real blocks whose field was
        fitted to ring maps: the ring maps sit exactly on the photos' rings, a fitted field's
        ARF only roughly, and its ring phase (earlywood vs latewood side) is not known.
        "auto" (default): "arf" when ``field`` is the block's true field (synthetic blocks) or
        a photo face lacks a ring map, else "ring_map".
    cache_dir : folder for the cached volumes and weights, default :func:`default_cache_dir`;
        ``False`` disables the cache.
    progress : bool
        tqdm bars on stderr over the networks' training steps (default True).
    threads : int or None
        ``torch.set_num_threads`` while training (None leaves torch's setting; default 1,
        :func:`~.translation.train_translation`).
    detail : bool
        Store the networks' ring input and the local slope of colour over it with the volumes
        (:func:`~.volumes.guide_slopes`), so that lookups add the detail of the field's exact
        rings inside each cell instead of blurring them over a cell (0.8 mm at the default
        resolution of a 100 mm block; its stair-stepped rings showed on bevels).

    Returns
    -------
    NeuralAppearance
        ``meta`` holds the cache key, whether the cache was hit, timings and notes.
    """
    field = block.true_field if field is None else field
    if source == "auto":
        maps = all(block.faces[f].ring_map is not None for f in photo_faces(block))
        source = "ring_map" if maps and field is not block.true_field else "arf"
    if source not in ("arf", "ring_map"):
        raise WoodcamError(f"source must be one of auto, arf, ring_map; got {source!r}")
    if field is None or not callable(field):
        raise WoodcamError(
            f"field must be a growth field (callable (n, 3) mm -> years) to build colour volumes of "
            f"block {block.name!r}; got {type(field).__name__}; fit one first"
        )
    if not photo_faces(block):
        raise NoPhotosError(
            f"block {block.name!r} has no face photos to train the neural appearance on; "
            "add photos or use the colour map (appearance='colormap')"
        )
    grid = VolumeGrid(block.size_mm, resolution)
    spec = translation_spec(quality, epochs, seed)
    settings = {"version": CACHE_VERSION, "grid": grid.to_dict(), "spec": spec.to_dict(),
                "orientation": orientation, "source": source, "detail": bool(detail)}
    key = cache_key(block, field, settings)
    if cache_dir is False:
        return NeuralAppearance(_build_volumes(block, field, grid, spec, settings, key, orientation,
                                               source, detail, progress, threads, None))
    from .._cache import entry_path, load_or_build

    path = entry_path(cache_dir or default_cache_dir(), block.name, key)
    built: dict = {}

    def build():
        vols = _build_volumes(block, field, grid, spec, settings, key, orientation, source, detail,
                              progress, threads, path)
        built["nets"] = vols.meta.pop("_nets")
        return vols

    def save(vols, tmp):
        # the weights first, then the volumes: the volumes' entry exists only when both do
        _save_nets(path.with_name(path.stem + ".weights.npz"), built["nets"])
        vols.save(tmp)

    vols, hit = load_or_build(path, load=_load_volumes, build=build, save=save,
                              what=f"neural appearance of block {block.name!r}")
    if hit:
        vols.meta["cache"] = "hit"
    vols.meta["cache_path"] = str(path)
    return NeuralAppearance(vols)


def _load_volumes(path: Path) -> ColorVolumes:
    vols = ColorVolumes.load(path)
    if path.stem.rsplit("-", 1)[-1] != vols.meta.get("key"):
        raise WoodcamError(f"{path}: holds volumes of key {vols.meta.get('key')!r}, not of its name")
    return vols


def _build_volumes(block, field, grid, spec, settings, key, orientation, source, detail, progress,
                   threads, path) -> ColorVolumes:
    """Train the translation networks and translate the field's volume (the expensive part)."""
    t0 = time.perf_counter()
    trained = train_axis_networks(block, grid, spec, field=field, source=source,
                                  orientation=orientation, progress=progress, threads=threads)
    t1 = time.perf_counter()
    years = years_volume(field, grid)
    axes = range(3) if orientation == "dependent" else [2]
    nets = trained["nets"]
    made = [translate_volume(nets[i], years, grid, k, source, return_guide=True) for i, k in enumerate(axes)]
    vols = np.stack([m[0] for m in made])
    t2 = time.perf_counter()
    guides = slopes = None
    if detail:
        guides = np.stack([m[1] for m in made])
        slopes = np.stack([guide_slopes(v, g) for v, g in zip(vols, guides)])
    t3 = time.perf_counter()
    meta = {"key": key, "settings": settings, "block": block.name, "cache": "miss" if path else "off",
            "train_s": round(t1 - t0, 3), "apply_s": round(t2 - t1, 3), "detail_s": round(t3 - t2, 3),
            "net_train_s": [round(n.train_seconds, 3) for n in nets],
            "net_final_l1": [round(n.final_l1, 5) for n in nets], "notes": trained["notes"]}
    if path is not None:
        meta["_nets"] = nets  # handed to the cache writer, not stored in the file
    return ColorVolumes(grid, vols, meta, guides, slopes)


def _save_nets(path: Path, nets) -> None:
    arrays, heads = {}, []
    for i, net in enumerate(nets):
        st = net.state()
        for k, v in st.pop("weights").items():
            arrays[f"net{i}/{k}"] = v
        heads.append(st)
    from .._atomic import atomic_path

    with atomic_path(path, mkdir=True) as tmp:
        np.savez(tmp, header=json.dumps(heads), **arrays)


def load_nets(path) -> list[TranslationNet]:
    """The translation networks saved next to cached volumes (``*.weights.npz``).

    A missing, empty, cut or foreign file, or weights of another network than their header, is
    one WoodcamError line naming the file (:func:`woodcam._readers.read_npz`): they were numpy's
    ``BadZipFile`` or ``EOFError`` and torch's many-line ``load_state_dict`` error."""
    from .._readers import read_npz

    fix = ("delete it and its colour volumes (woodcam cache clear --kind appearance): the next fit "
           "trains and saves them again")
    with read_npz(path, "the neural appearance's network weights (*.weights.npz beside cached colour volumes)",
                  fix) as z:
        heads = json.loads(str(z["header"]))
        if not isinstance(heads, list) or not all(isinstance(st, dict) for st in heads):
            raise ValueError(f"its header is not a list of networks; got {received(heads)}")
        out = []
        for i, st in enumerate(heads):
            pre = f"net{i}/"
            st["weights"] = {k[len(pre):]: z[k] for k in z.files if k.startswith(pre)}
            out.append(TranslationNet.from_state(st))
    return out


def block_appearance(block: Block, field: GrowthFieldLike, kind: AppearanceKind = "colormap", *,
                     species: str = "oak", **neural_params) -> AppearanceLike:
    """The appearance of ``block``: its photo-fitted colour map or its neural volumes.

    ``kind="neural"`` on a block without photos falls back to the species colour map and says
    so with an :class:`AppearanceFallbackWarning`, naming the training settings in
    ``neural_params`` it then ignores (``quality``, ``epochs`` ...: they were taken without a
    word). ``neural_params`` go to :func:`fit_neural_appearance`. ``field``: the block's growth
    field, ``(n, 3) mm (block frame) -> (n,) years``, that the colour map is fitted along
    (:meth:`ColorMapAppearance.fit_to_block`) or the networks read; ``species``: the colour
    map's species (the fallback's too; a fitted neural appearance does not use it).
    """
    if kind not in APPEARANCE_KINDS:
        raise WoodcamError(f"appearance must be one of {', '.join(APPEARANCE_KINDS)}; got {kind!r}")
    has_photos = bool(photo_faces(block))
    if kind == "neural":
        if has_photos:
            return fit_neural_appearance(block, field, **neural_params)
        # where the cache lives and whether a bar shows change no colour: not worth a word
        ignored = [f"--{k.replace('_', '-')} {v}" for k, v in neural_params.items()
                   if k not in ("cache_dir", "progress", "threads") and v is not None]
        warnings.warn(AppearanceFallbackWarning(
            f"block {block.name!r} has no face photos to learn a neural appearance from; "
            f"using the {species} colour map instead"
            + (f", and {', '.join(ignored)} (neural training settings) have no effect; add face "
               "photos to the block or drop them" if ignored else "")), stacklevel=2)
    if has_photos:
        return ColorMapAppearance.fit_to_block(block, field, species)
    return ColorMapAppearance(species)
