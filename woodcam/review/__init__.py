"""The one-file review page: a baked part in a three.js viewer with a live section plane whose
cap shows the real wood inside, views, measurement, face photos, the bake report and hotspots.

Data form
---------
:func:`write_review` writes ONE self-contained HTML file (works from ``file://``, no network):

* the viewer: ``viewer.bundle.js`` beside this module, made by ``make review-bundle`` from
  ``viewer_src.js`` and three.js (npm, version in :data:`THREE_VERSION`) with esbuild; it is
  committed with three.js' licence (``THREE_LICENSE``) so installs need no npm;
* the part: the GLB (metres, Y up, as exported) base64-encoded;
* the wood inside: three colour volumes over the block, one per cut axis (``Wood.color`` at
  voxel centres with the normal of that axis, eq. 10 of seed 000 depends on it), each a
  lossless WebP of tiled z slices (a third smaller than a PNG, which cannot predict real wood's
  busier rings: a 50 mm Mokume cube's three PNGs took 3.2 MiB in base64, over the page's 3 MiB;
  lossless WebP is read by Chrome 32+, Firefox 65+ and Safari 14+ on macOS 11+ / iOS 14+ (Safari
  14-15 on older macOS cannot, and the page then says so)); the cap shader samples them trilinearly, so the
  cap shows ``Wood.color`` up to the voxel size (:func:`volume_cell_mm`);
* the report (block, size, placement, texel density and anything the caller adds), the block's
  face photos where it has them, and hotspots (knots, G-code warnings) with positions in mm.

Size: at most 3 MiB besides the part's GLB at the default voxels, photographed blocks included
(``tests/review``), 3.5 MiB with the neural appearance, whose volumes carry the photos' fine
texture: a low-amplitude noise that no lossless codec shrinks, and fewer voxels or a lossy codec
would blur the texture that model was chosen for.
"""

from __future__ import annotations

import base64
import html
import io
import json
import math
import shlex
from pathlib import Path

import numpy as np

from ..errors import WoodcamError
from ..limits import REVIEW_VOXELS_RANGE

_HERE = Path(__file__).resolve().parent
#: What :func:`write_review` reads: the GLB woodcam bake (or gcode) wrote, with its metadata.
PART_SUFFIXES = (".glb",)
#: three.js version the committed bundle was built from (``make review-bundle``).
THREE_VERSION = "0.187.0"
#: Voxels per colour volume (one per cut axis): three volumes of this many RGB voxels keep the
#: page near 2 MB (lossless WebP) with ~1 mm voxels on a 100 x 80 x 50 mm block, 0.7 mm on a
#: 50 mm cube.
VOLUME_VOXELS = 400_000
#: Longest string Chrome's JavaScript can hold (V8's String::kMaxLength on 64-bit, 2^29 - 24
#: characters; Firefox allows 2^30 - 2): the page reads its part as one base64 string, so a GLB
#: over ~402 MB (4/3 of it in base64) can never be shown.
MAX_PAGE_STRING = 2**29 - 24


def volume_cell_mm(size_mm, voxels: int = VOLUME_VOXELS) -> float:
    """Edge (mm) of the cubic voxels of a colour volume over a block of ``size_mm (3,)``."""
    return float(np.cbrt(np.prod(np.asarray(size_mm, dtype=float)) / voxels))


def colour_volume(wood, size_mm, axis: str, cell_mm: float) -> np.ndarray:
    """``Wood.color`` at the voxel centres ``(i + 0.5) * size / n`` of the block, normal = +axis.

    Returns
    -------
    (nz, ny, nx, 3) uint8
        sRGB colours, z-major (the cap samples them at block point p as p / size).
    """
    size = np.asarray(size_mm, dtype=float)
    shape = np.maximum(1, np.ceil(size / cell_mm).astype(int))
    axes = [(np.arange(n) + 0.5) * s / n for n, s in zip(shape, size)]
    z, y, x = np.meshgrid(axes[2], axes[1], axes[0], indexing="ij")
    points = np.column_stack([x.ravel(), y.ravel(), z.ravel()])
    normals = np.zeros_like(points)
    normals[:, "xyz".index(axis)] = 1.0
    from ..appearance.wood import wood_colors

    # the checked seam: a user's wood's NaN or 0..255 colours were written as black or white
    # voxels, a wrong shape was numpy's reshape error
    rgb = np.asarray(wood_colors(wood, points, normals), dtype=np.float64)
    return np.round(np.clip(rgb, 0.0, 1.0) * 255).astype(np.uint8).reshape(*shape[::-1], 3)


def _tiled_image(volume: np.ndarray) -> tuple[str, int]:
    """(nz, ny, nx, 3) -> a lossless WebP data URL of the z slices tiled ``tiles`` across, and
    ``tiles``."""
    from PIL import Image

    nz, ny, nx, _ = volume.shape
    tiles = max(1, min(nz, int(math.ceil(math.sqrt(nz * ny / nx)))))
    rows = int(math.ceil(nz / tiles))
    sheet = np.zeros((rows * ny, tiles * nx, 3), dtype=np.uint8)
    for k in range(nz):  # one copy per slice (nz ~ 50-100), not per voxel
        r, c = divmod(k, tiles)
        sheet[r * ny:(r + 1) * ny, c * nx:(c + 1) * nx] = volume[k]
    buf = io.BytesIO()
    # lossless: the cap must show Wood.color, not a codec's guess; method 4 is within 1 % of the
    # smallest (6) at a tenth of its time
    Image.fromarray(sheet).save(buf, format="WEBP", lossless=True, method=4)
    return "data:image/webp;base64," + base64.b64encode(buf.getvalue()).decode("ascii"), tiles


def _photo_urls(photos: dict | None) -> dict:
    """face -> small JPEG data URL of each face photo (longest side 320 px)."""
    from PIL import Image

    out = {}
    for face, image in (photos or {}).items():
        img = Image.fromarray(np.asarray(image)) if not isinstance(image, Image.Image) else image
        img = img.convert("RGB")
        img.thumbnail((320, 320))
        buf = io.BytesIO()
        img.save(buf, format="JPEG", quality=80)
        out[face] = "data:image/jpeg;base64," + base64.b64encode(buf.getvalue()).decode("ascii")
    return out


def write_review(glb_path, out_html, *, wood, size_mm, title: str | None = None,
                 report: dict | None = None, photos: dict | None = None,
                 hotspots: list[dict] | None = None, voxels: int = VOLUME_VOXELS,
                 progress: bool = False) -> Path:
    """Write the review page of a baked part.

    Parameters
    ----------
    glb_path : path
        A GLB written by :func:`woodcam.export.export_glb` (metres, Y up).
    out_html : path
        The ``.html`` file to write (atomically).
    wood : Wood
        The block's wood (``color(points_mm, normals)``), for the section cap.
    size_mm : (3,) float
        Block size (W, D, H) in mm.
    title : str, optional
        Page title (default: the GLB's stem).
    report : dict, optional
        Key/value lines shown in the side panel and the printed shop sheet.
    photos : dict face -> (h, w, 3) uint8 image, optional
        The block's face photos, shown in the side panel.
    hotspots : list of dict, optional
        ``{"kind": "knot" | "gcode", "label": str, "at_mm": [x, y, z]}``, block frame.
    voxels : int
        Voxels per colour volume (see :data:`VOLUME_VOXELS`).
    progress : bool
        A bar over the three colour volumes (seconds each at a few million voxels).
    """
    from .._atomic import check_output_path, write_bytes

    glb_path = Path(glb_path)
    if not glb_path.is_file() or glb_path.suffix.lower() not in PART_SUFFIXES:
        raise WoodcamError(
            f"review: the part must be an existing .glb file written by woodcam bake; got "
            f"{str(glb_path)!r}")
    out_html = check_output_path(out_html, suffixes=(".html",), what="review --out", mkdir=True)
    bundle = _HERE / "viewer.bundle.js"
    if not bundle.is_file():
        raise WoodcamError(
            f"review: the viewer bundle {bundle} is missing; rebuild it with 'make review-bundle'")
    lo, hi = REVIEW_VOXELS_RANGE
    if not (isinstance(voxels, int) and lo <= voxels <= hi):
        raise WoodcamError(f"review: voxels must be an integer in [{lo}, {hi:g}]; got {voxels!r}")
    from ..frames import check_size

    size = [float(v) for v in check_size(size_mm)]  # a 0 or negative size wrote a page
    hotspots = _checked_hotspots(hotspots)
    report = _checked_report(report)
    part_glb = _part_glb_bytes(glb_path)  # before the seconds of colour volumes
    _check_part_in_block(glb_path, part_glb, size)
    if 4 * math.ceil(len(part_glb) / 3) > MAX_PAGE_STRING:
        raise WoodcamError(
            f"review: {str(glb_path)!r} is {len(part_glb) / 2**20:.0f} MiB; the page holds it as one "
            f"base64 string, which browsers cap at {MAX_PAGE_STRING:,} characters (Chrome), so at most "
            f"{MAX_PAGE_STRING // 4 * 3 / 2**20:.0f} MiB; bake the part with a smaller texture "
            "(--max-atlas, --texels-per-mm)")
    cell = volume_cell_mm(size, voxels)
    from .._progress import progress_bar

    volumes = {}
    for axis in progress_bar("xyz", desc="review: colour volumes", unit="volume", enabled=progress):
        vol = colour_volume(wood, size, axis, cell)
        image, tiles = _tiled_image(vol)
        volumes[axis] = {"image": image, "tiles": tiles, "shape": [vol.shape[2], vol.shape[1], vol.shape[0]]}
    data = {
        "title": title or glb_path.stem,
        "block": {"size_mm": size, "voxel_mm": cell},
        "report": report,
        "hotspots": hotspots,
        "photos": _photo_urls(photos),
        "volumes": volumes,
    }
    page = _page(data, base64.b64encode(part_glb).decode("ascii"),
                 bundle.read_text(encoding="utf-8"))
    write_bytes(out_html, page.encode("utf-8"))
    return out_html


def _checked_report(report) -> dict:
    """``report`` as plain JSON with string keys: a NaN was written as a bare NaN that the
    page's JSON.parse refused, and a numpy array was json's TypeError after the colour volumes."""
    if report is None:
        return {}
    if not isinstance(report, dict):
        raise WoodcamError(f"review: report must be a dict of rows; got {type(report).__name__}")
    try:  # strict, as export_glb's metadata
        return json.loads(json.dumps({str(k): v for k, v in report.items()}, allow_nan=False))
    except (TypeError, ValueError) as err:
        raise WoodcamError(f"review: report must hold JSON values (strings, finite numbers, lists, "
                           f"dicts); got {err}; convert arrays with .tolist() and write NaN as "
                           "a string") from err


def _checked_hotspots(hotspots) -> list[dict]:
    """``hotspots`` as the page reads them: ``kind`` and ``label`` strings, ``at_mm`` three finite
    floats (a NaN was written as a bare NaN, which the page's JSON.parse refused, and a string
    broke the viewer's list: either left a page that said only 'error')."""
    from .._checks import check_vector

    if hotspots is None:
        return []
    if not isinstance(hotspots, (list, tuple)):
        raise WoodcamError(f"review: hotspots must be a list of dicts; got {type(hotspots).__name__}")
    out = []
    for i, spot in enumerate(hotspots):
        if not isinstance(spot, dict):
            raise WoodcamError(f"review: hotspots[{i}] must be a dict with 'kind', 'label' and "
                               f"'at_mm'; got {type(spot).__name__}")
        at = check_vector(spot.get("at_mm"), f"review: hotspots[{i}]['at_mm']",
                          fix="a point in the block frame, mm, e.g. [50, 40, 25]")
        out.append({"kind": str(spot.get("kind", "")), "label": str(spot.get("label", "")),
                    "at_mm": [float(v) for v in at]})
    return out


def _part_bounds(glb_path: Path, part_glb: bytes) -> np.ndarray:
    """``(2, 3)`` bounds (mm, block frame) of the part the page shows, ``part_glb`` (a woodcam
    GLB: block-frame mm in its vertex buffer under the root transform): its POSITION accessors'
    min and max, which glTF requires, read from the JSON chunk without decoding the texture;
    :func:`woodcam.export.load_textured` where a file lacks them."""
    from ..export import glb_json

    try:
        tree = glb_json(part_glb, f"review: {str(glb_path)!r}")
        accessors = [tree["accessors"][p["attributes"]["POSITION"]]
                     for m in tree["meshes"] for p in m["primitives"]]
        lo = np.min([a["min"] for a in accessors], axis=0)
        hi = np.max([a["max"] for a in accessors], axis=0)
        bounds = np.array([lo, hi], dtype=float)
        if bounds.shape == (2, 3) and np.isfinite(bounds).all():
            return bounds
    except (WoodcamError, ValueError, KeyError, TypeError, IndexError):
        pass  # no min/max: read the mesh itself
    from ..export import load_textured

    return np.asarray(load_textured(glb_path).bounds, dtype=float)


def _check_part_in_block(glb_path: Path, part_glb: bytes, size: list[float]) -> None:
    """Refuse a part wholly outside the ``size`` mm block, and warn of one reaching past it:
    :func:`woodcam.frames.check_part_in_block`, the check preview makes too."""
    from ..frames import check_part_in_block

    lo, hi = _part_bounds(glb_path, part_glb)
    check_part_in_block(lo, hi, size, f"review: {str(glb_path)!r}", shows="the page's section", stacklevel=4)


def _part_glb_bytes(glb_path: Path) -> bytes:
    """The GLB the page shows: ``glb_path``'s bytes when woodcam wrote it (block-frame mm under
    the root transform :data:`woodcam.frames.BLOCK_TO_GLTF`); another program's textured GLB
    written again by :func:`woodcam.export.export_glb` from :func:`woodcam.export.load_textured`,
    so the page places it where every other command reads it (a trimesh GLB in mm was shown
    1000 times too large, as metres, while its hotspots stood in mm); an untextured one is an
    error (it drew a blank view that said 'ready')."""
    import tempfile

    from ..export import export_glb, load_textured, written_by_woodcam

    if written_by_woodcam(glb_path):
        return glb_path.read_bytes()
    mesh = load_textured(glb_path)
    if getattr(mesh.visual, "kind", None) != "texture" or getattr(mesh.visual, "uv", None) is None:
        raise WoodcamError(
            f"review: {str(glb_path)!r} was not written by woodcam and carries no texture: the "
            "page shows a baked part; bake it first, e.g. woodcam bake "
            f"{shlex.quote(str(glb_path))} --block SPEC --out baked.glb")
    with tempfile.TemporaryDirectory(prefix="woodcam-review-") as tmp:
        return export_glb(mesh, Path(tmp) / "part.glb").read_bytes()


#: Runs before the viewer: an error the viewer does not catch itself (no WebGL 2: three.js'
#: renderer throws before the viewer's main() runs; a damaged page) left the page saying
#: "loading" for ever over an empty view. Every error, the viewer's own included (its main()
#: writes "error: ..." into #status), is shown over the view and in the title.
_FAILURE_SCRIPT = """
(() => {
  const status = document.getElementById('status');
  const show = (text) => {
    let box = document.getElementById('failure');
    if (!box) {
      box = document.createElement('p');
      box.id = 'failure';
      box.style.cssText = 'position:fixed;top:12px;left:12px;max-width:45%;margin:0;padding:10px;'
        + 'background:#fff0ee;border:1px solid #c03020;color:#601010;z-index:9';
      document.body.appendChild(box);
    }
    box.textContent = text;
  };
  const fail = (msg) => {
    if (status.textContent.startsWith('error')) return;  // the first error says why
    status.textContent = `error: ${msg}`;
    document.title = `error: ${msg}`;
  };
  new MutationObserver(() => {
    if (status.textContent.startsWith('error')) show(status.textContent);
  }).observe(status, { childList: true, characterData: true, subtree: true });
  window.addEventListener('error', (e) => fail(e.error || e.message));
  window.addEventListener('unhandledrejection', (e) => fail(e.reason));
  if (!document.createElement('canvas').getContext('webgl2')) {
    fail('this browser gives the page no WebGL 2, which its 3-D view needs: turn on hardware '
         + 'acceleration (or WebGL) in the browser settings, or open the page in a current '
         + 'Chrome, Edge, Firefox or Safari');
  }
})();
"""


def _page(data: dict, glb_b64: str, bundle: str) -> str:
    title = html.escape(data["title"])
    report_rows = "".join(
        f"<tr><th>{html.escape(k)}</th><td>{html.escape(v if isinstance(v, str) else json.dumps(v))}</td></tr>"
        for k, v in data["report"].items())
    photos = "".join(
        f'<figure><img src="{url}" alt="face {html.escape(face)}"><figcaption>{html.escape(face)}'
        "</figcaption></figure>" for face, url in data["photos"].items())
    W, D, H = data["block"]["size_mm"]
    # JSON inside <script>: "</" must not close the element
    payload = json.dumps(data).replace("</", "<\\/")
    licence = (_HERE / "THREE_LICENSE").read_text(encoding="utf-8") if (_HERE / "THREE_LICENSE").is_file() else ""
    return f"""<!doctype html>
<html lang="en"><head><meta charset="utf-8"><title>{title}</title>
<meta name="viewport" content="width=device-width, initial-scale=1">
<style>
 html, body {{ margin: 0; height: 100%; font: 14px system-ui, sans-serif; color: #222; }}
 #wrap {{ display: flex; height: 100%; }}
 #view {{ flex: 1; min-width: 0; height: 100%; display: block; }}
 #panel {{ width: 320px; overflow: auto; padding: 10px 14px; background: #f6f3ee;
          border-left: 1px solid #ccc; }}
 #panel h1 {{ font-size: 17px; margin: 4px 0 8px; }}
 #panel h2 {{ font-size: 14px; margin: 14px 0 4px; }}
 #panel .frame {{ font-size: 12px; margin: 0 0 8px; }}
 #panel table {{ border-collapse: collapse; width: 100%; font-size: 12px; }}
 #panel th {{ text-align: left; padding-right: 6px; vertical-align: top; }}
 figure {{ display: inline-block; margin: 2px; }} figure img {{ width: 90px; }}
 figcaption {{ font-size: 11px; text-align: center; }}
 #hotspots li {{ cursor: pointer; }} #hotspots li.focused {{ font-weight: bold; }}
 #snapshot {{ display: none; }}
 body.bare #panel {{ display: none; }}
 .print-only {{ display: none; }}
 @media print {{ #view, button, .ui, #status {{ display: none !important; }}
   #snapshot {{ display: block; max-width: 100%; max-height: 14cm; margin: 6px 0; }}
   .print-only {{ display: block; }} #wrap {{ display: block; }}
   #panel {{ width: auto; border: 0; background: none; }} }}
</style></head>
<body><div id="wrap"><canvas id="view"></canvas>
<div id="panel"><h1>{title}</h1>
<p class="frame">Lengths in mm, in the block frame: origin at the block's bottom-front-left corner,
 x to the right (width), y away from the front (depth), z up (height); the arrows at the origin
 are x (red), y (green), z (blue).</p>
<p id="sheet-state" class="print-only"></p><img id="snapshot" alt="view">
<div class="ui"><b>View</b>
 <button data-view="front">front</button><button data-view="top">top</button>
 <button data-view="left">left</button><button data-view="iso">iso</button>
 <label><input type="checkbox" id="ortho"> orthographic</label></div>
<h2 class="ui">Section</h2><div class="ui">
 <label><input type="checkbox" id="cut-on"> cut</label>
 <select id="cut-axis"><option>x</option><option>y</option><option>z</option></select>
 <input type="range" id="cut-pos" min="0" step="0.1" style="width:150px"> <span id="cut-label"></span>
 <p style="font-size:12px">The cut face shows the wood inside the block
 (Wood.color on {data['block']['voxel_mm']:.2f} mm voxels). The top view shows the part's outside
 uncut until you tick cut.</p></div>
<h2 class="ui">Measure</h2><div class="ui"><label><input type="checkbox" id="measure"> two clicks on the
 part</label><div id="measurement"></div></div>
<h2>Block and bake</h2><table><tr><th>block</th><td>{W:.5g} x {D:.5g} x {H:.5g} mm (x, y, z)</td></tr>\
{report_rows}</table>
<h2>Hotspots</h2>{'<ul id="hotspots"></ul>' if data['hotspots'] else '<i id="hotspots">none</i>'}
<h2>Face photos</h2><div>{photos or '<i>none</i>'}</div>
<p><button id="print">print shop sheet</button> <span id="status">loading</span></p>
<div id="probe" hidden></div>
</div></div>
<script type="application/json" id="woodcam-data">{payload}</script>
<script type="text/plain" id="woodcam-glb">{glb_b64}</script>
<script>if (new URLSearchParams(location.hash.slice(1)).has('bare')) document.body.classList.add('bare');</script>
<script>{_FAILURE_SCRIPT}</script>
<!-- three.js r{THREE_VERSION[2:5]} (MIT licence below), bundled with the woodcam viewer by esbuild.
{html.escape(licence)}-->
<script>{bundle}</script>
</body></html>
"""
