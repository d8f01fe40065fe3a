"""Regenerate docs/img/knot_cone_7777.png: cut planes of dev seed 7777 block 2 (six noisy
faces), the plain stem, the stem bent round strands through the exits' centroids (before FIT_VERSION 10)
and round the cones fitted to the knot masks (the default fit's strands since FIT_VERSION 10).

    python docs/img/make_knot_cone.py
"""

import warnings
from pathlib import Path

from PIL import Image

import woodcam.inference.knots as K
from woodcam.bench_realistic import BENCH_PIXEL_MM, make_block
from woodcam.inference.evaluate import DEFAULT_PLANES, evaluate_fits, plot_planes
from woodcam.inference.observations import gather_observations
from woodcam.inference.stem import fit_stem

OUT = Path(__file__).parent / "knot_cone_7777.png"


def main():
    warnings.simplefilter("ignore")
    block, info = make_block(7777, 2, "noisy", "realistic", 256)
    obs = gather_observations(block)
    stem = fit_stem(obs, block.size_mm)
    exits = K.knot_exits(block)
    old = K.fit_knotted_stem(obs, block.size_mm, exits, stem=stem)
    new = K.fit_knotted_stem(obs, block.size_mm, exits, stem=stem, cones=True)
    fields = {"plain stem": stem, "bend, centroid strands": old, "bend, cone strands": new}
    sc = evaluate_fits(block.true_field, fields, block.size_mm, DEFAULT_PLANES, BENCH_PIXEL_MM, keep_lines=True)
    for k, v in sc.items():
        print(f"{k}: {v[0]['matched_1']:.1f} / {v[0]['matched_2']:.1f} % within 1 / 2 mm")
    plot_planes(OUT, {k: v[1] for k, v in sc.items()},
                title=f"dev seed 7777 {info['name']} (six faces, noisy): black = true rings")
    Image.open(OUT).convert("RGB").quantize(64).save(OUT, optimize=True)


if __name__ == "__main__":
    main()
