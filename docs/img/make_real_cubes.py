"""Parts baked from the real Mokume cubes next to their photos (docs/img/real_cubes_*.png).

    WOODCAM_SHARED_DATA=/path/to/shared/data python docs/img/make_real_cubes.py [H11 CN03] [--out DIR]

For each sample: the cube inset by 1 mm and the raised-panel lid of ``cad_examples/lid.py``
(scaled by 1/2 to fit the 50 mm cube) are carved from the sample's stock (its field fitted to
its ring maps, :func:`woodcam.stock.open_stock`), baked with the photo-fitted colour map and with
the neural appearance, and rendered off-screen from the front-right-top ("iso": faces A front,
E right and B top). Columns: the same cube textured with the sample's own photos (and, under
it, with its ring maps), so photo and bake are compared in the same view | colour map | neural.
Needs pyvista and build123d; about a minute per sample (the neural volumes are cached).
"""

from __future__ import annotations

import argparse
import os
import sys
import tempfile
from pathlib import Path

import numpy as np
from PIL import Image, ImageDraw

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT))

from woodcam.frames import FACE_NORMAL, block_to_pixel  # noqa: E402

OUT = Path(__file__).parent
TILE = 400            # rendered tile side, pixels
INSET_MM = 1.0        # the cube part is the block inset by this much on every face


class FaceImageWood:
    """A "wood" that shows a block's face images: the image of the face the normal points to,
    sampled bilinearly at the point's in-plane coordinates (conventions.md pixel mapping).
    Lets a photo be rendered in exactly the same view as a baked part."""

    def __init__(self, block, kind: str = "photo"):
        self.block, self.kind = block, kind

    def color(self, points_mm, normals):
        from scipy import ndimage

        p = np.asarray(points_mm, float)
        n = np.asarray(normals, float)
        names = list(FACE_NORMAL)
        dirs = np.array([FACE_NORMAL[f] for f in names], float)
        which = np.argmax(n @ dirs.T, axis=1)
        out = np.full((len(p), 3), 0.5, np.float32)
        for k, face in enumerate(names):
            idx = np.flatnonzero(which == k)
            f = self.block.faces.get(face)
            img = None if f is None else (f.photo if self.kind == "photo" else f.ring_map)
            if not len(idx) or img is None:
                continue
            img = np.asarray(img, np.float32) / (255.0 if self.kind == "photo" else 1.0)
            img = np.repeat(img[..., None], 3, axis=2) if img.ndim == 2 else img
            r, c = block_to_pixel(face, p[idx], img.shape[:2], self.block.size_mm)
            for ch in range(3):
                out[idx, ch] = ndimage.map_coordinates(img[..., ch], [r, c], order=1, mode="nearest")
        return np.clip(out, 0, 1)


def _parts(size_mm):
    from manifold3d import Manifold

    from woodcam.cad import load_part

    w, d, h = size_mm
    cube = Manifold.cube((w - 2 * INSET_MM, d - 2 * INSET_MM, h - 2 * INSET_MM)).translate(
        (INSET_MM, INSET_MM, INSET_MM))
    lid = load_part(ROOT / "cad_examples" / "lid.py").scale((0.5, 0.5, 0.5))
    lo = np.asarray(lid.bounding_box()[:3])
    hi = np.asarray(lid.bounding_box()[3:])
    shift = np.asarray(size_mm) / 2 - (lo + hi) / 2
    shift[2] = h - 4.0 - hi[2]        # lid top 4 mm under the block's top face
    return {"cube": cube, "lid": lid.translate(tuple(shift))}


#: Views: "front-right" shows faces A (front), E (right), B (top) as the "iso" camera does;
#: "back-left" turns the part 180 deg about the vertical axis first, showing F, C and B.
VIEWS = {"front-right": "A front, E right, B top", "back-left": "F front, C right, B top"}


def _render(part, wood, size_mm, view: str = "front-right", texels_per_mm: float = 8.0) -> np.ndarray:
    from woodcam.bake import bake
    from woodcam.cad import carve
    from woodcam.view import preview

    mesh = carve(part, size_mm).mesh
    baked = bake(mesh, wood, texels_per_mm=texels_per_mm)
    if view == "back-left":
        turn = np.diag([-1.0, -1.0, 1.0, 1.0])
        turn[:3, 3] = [size_mm[0], size_mm[1], 0.0]
        baked.mesh.apply_transform(turn)
    with tempfile.TemporaryDirectory() as tmp:
        png = Path(tmp) / "v.png"
        preview(baked.mesh, screenshot=png, window_size=(TILE, TILE), cut_plane=False, camera="iso")
        return np.asarray(Image.open(png).convert("RGB"))


#: The view of each sample: H11's knot exits through faces C and F (its back-left edge).
SAMPLE_VIEW = {"H11": "back-left"}

#: Colour-map species (pores, streaks) of each sample, from the data's README: the Mokume files
#: carry no species. The colours themselves are fitted to the photos.
SAMPLE_SPECIES = {"H11": "spruce", "CN03": "oak"}


def real_cube_figure(sample: str, out_path, *, data_dir=None, quality: str = "normal",
                     view: str | None = None) -> Path:
    """Write the side-by-side figure of one Mokume sample (module docstring); returns the path."""
    from woodcam.stock import open_stock

    data = Path(data_dir or os.environ.get("WOODCAM_SHARED_DATA") or ROOT.parent / "shared" / "data")
    folder = data / "mokume" / sample
    cm = open_stock(str(folder), appearance="colormap", species=SAMPLE_SPECIES.get(sample))
    nn = open_stock(str(folder), appearance="neural", quality=quality, progress=False)
    from woodcam.block.io import read_mokume

    block = read_mokume(folder)
    parts = _parts(cm.size_mm)
    photo, rings = FaceImageWood(block, "photo"), FaceImageWood(block, "ring_map")
    view = view or SAMPLE_VIEW.get(sample, "front-right")
    size = cm.size_mm
    tiles = [[(f"photos ({VIEWS[view]})", _render(parts["cube"], photo, size, view)),
              ("colour map", _render(parts["cube"], cm.wood, size, view)),
              ("neural", _render(parts["cube"], nn.wood, size, view))],
             [("ring maps (Mokume U-Net)", _render(parts["cube"], rings, size, view)),
              ("colour map", _render(parts["lid"], cm.wood, size, view)),
              ("neural", _render(parts["lid"], nn.wood, size, view))]]
    label = 18
    canvas = Image.new("RGB", (3 * TILE, 2 * (TILE + label) + label), "white")
    draw = ImageDraw.Draw(canvas)
    draw.text((4, 2), f"Mokume {sample}, 50 mm cube: field fitted to its ring maps; "
              "inset cube and raised-panel lid (x0.5)", fill=(0, 0, 0))
    for r, row in enumerate(tiles):
        for c, (name, im) in enumerate(row):
            y = label + r * (TILE + label)
            canvas.paste(Image.fromarray(im), (c * TILE, y + label))
            draw.text((c * TILE + 4, y + 3), name, fill=(0, 0, 0))
    out_path = Path(out_path)
    out_path.parent.mkdir(parents=True, exist_ok=True)
    canvas.quantize(128).save(out_path, optimize=True)
    return out_path


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("samples", nargs="*", default=["H11", "CN03"])
    p.add_argument("--out", type=Path, default=OUT)
    p.add_argument("--quality", default="normal", choices=("draft", "normal", "high"))
    a = p.parse_args(argv)
    for s in a.samples:
        print(real_cube_figure(s, a.out / f"real_cubes_{s}.png", quality=a.quality))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
