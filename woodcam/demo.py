"""The end-to-end demo: carve the example parts out of a built-in block and preview them."""

from __future__ import annotations

import time
from dataclasses import dataclass, field
from pathlib import Path

from ._atomic import atomic_path
from ._progress import StageBar
from .errors import WoodcamError
from .pipeline import PartPreview, preview_part
from .stock import open_stock

#: The example parts the demo carves, with the built-in block each comes from.
DEMO_PARTS: tuple[tuple[str, str], ...] = (
    ("bowl.py", "builtin:flat-sawn"),       # build123d, turned from side grain
    ("tray.py", "builtin:quarter-sawn"),    # cadquery, pocket and chamfers
    ("lid.py", "builtin:rift"),             # bevels that cut across the rings at an angle
)


def examples_dir() -> Path:
    """The example part scripts, installed with the package (``woodcam/examples``; the
    repository's ``cad_examples/`` is a link to it)."""
    d = Path(__file__).resolve().parent / "examples"
    if not d.is_dir():
        raise WoodcamError(f"the example parts are missing from {d}; reinstall woodcam")
    return d


@dataclass
class DemoReport:
    parts: list[PartPreview] = field(default_factory=list)
    total_s: float = 0.0
    overview: Path | None = None

    def summary(self) -> str:
        """A plain-text table: one row per part, one column per stage (seconds)."""
        stages = ["load", "carve", "bake", "export", "render"]
        head = f"{'part':<10}{'block':<24}{'tris':>8}{'atlas':>11}" + "".join(f"{s:>8}" for s in stages)
        rows = [head, "-" * len(head)]
        for p in self.parts:
            atlas = f"{p.atlas_px[1]}x{p.atlas_px[0]}"
            rows.append(f"{p.name:<10}{p.meta_block:<24}{p.triangles:>8}{atlas:>11}"
                        + "".join(f"{p.timings_s.get(s, 0.0):>8.2f}" for s in stages))
        rows.append(f"total {self.total_s:.1f} s; overview picture: {self.overview}; files:")
        for p in self.parts:
            rows.append("  " + ", ".join(str(f) for f in p.files.values()))
        for p in self.parts:
            rows += [f"warning ({p.name}): {w}" for w in p.warnings]
        return "\n".join(rows)


def run_demo(out_dir, *, quick: bool = False, texels_per_mm: float | None = None,
             progress: bool = True, appearance: str = "colormap", species: str | None = None,
             obj: bool = True, **appearance_params) -> DemoReport:
    """Carve, bake, export and render every part of :data:`DEMO_PARTS` into ``out_dir``.

    ``quick`` lowers the texel density (4 texels/mm instead of 10) for CI. ``appearance`` is
    ``"colormap"`` (fast, default) or ``"neural"`` (colour volumes learnt from each built-in
    block's rendered photos, cached; ``quick`` uses the "draft" quality). ``species``
    overrides every block's colour preset; ``obj`` writes OBJ+MTL+PNG beside each GLB;
    ``appearance_params`` go to :func:`~woodcam.stock.open_stock` (knot colours, or the neural
    ``quality``/``epochs``).
    """
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    tpm = texels_per_mm or (4.0 if quick else 10.0)
    report = DemoReport()
    t0 = time.perf_counter()
    names = [Path(script).stem for script, _ in DEMO_PARTS]
    # a bar over the parts, each part's own bar of its stages under it
    with StageBar([*names, "overview"], desc="demo", enabled=progress) as bar:
        for name, (script, spec) in zip(names, DEMO_PARTS):
            with bar.stage(name):
                params = dict(appearance_params)
                if appearance == "neural":
                    params.setdefault("quality", "draft" if quick else "normal")
                    params["progress"] = progress
                stock = open_stock(spec, appearance=appearance, species=species, **params)
                res = preview_part(examples_dir() / script, stock, out / f"{name}.glb",
                                   texels_per_mm=tpm, obj=obj, progress=progress)
            res.meta_block = spec
            report.parts.append(res)
        with bar.stage("overview"):
            report.overview = render_overview(report.parts, out / "demo.png")
    report.total_s = time.perf_counter() - t0
    return report


def render_overview(parts: list[PartPreview], png, *, tile_px: tuple[int, int] = (640, 520)) -> Path:
    """One picture of all demo parts side by side, whole (no cut plane), for a quick look."""
    import tempfile

    from PIL import Image

    from .view import preview

    tiles = []
    # the tiles in a scratch folder of their own: drawn beside demo.png as _<part>_tile.png they
    # wrote over and then deleted a file of that name there, and a stop left one behind
    with tempfile.TemporaryDirectory(prefix="woodcam-demo-") as scratch:
        for p in parts:
            tile = Path(scratch) / f"{p.name}_tile.png"
            preview(p.files["glb"], screenshot=tile, window_size=tile_px, cut_plane=False)
            with Image.open(tile) as im:
                tiles.append(im.convert("RGB"))
    strip = Image.new("RGB", (sum(t.width for t in tiles), max(t.height for t in tiles)), "white")
    x = 0
    for t in tiles:
        strip.paste(t, (x, 0))
        x += t.width
    with atomic_path(png) as tmp:
        strip.save(tmp)
    return Path(png)
