"""Regenerate docs/img/pith_pairs_50287.png: cut planes of seed 50287 block 1 (six noisy faces;
a knot cuts the front-left corner, another runs from the left face to the right one), the stem
bent round the knots' cones with the exits paired in distance order (FIT_VERSION 16: the corner
knot paired with the other knot's right exit, 79.9 against 80.5 mm) and paired by how near their
line passes the fitted pith (FIT_VERSION 17), against the true rings.

    python docs/img/make_pith_pairs.py
"""

import warnings
from pathlib import Path
from unittest import mock

from make_bend_takes_place import fields_on_planes  # (run from docs/img: its folder is on the path)

from woodcam.bench_realistic import make_block
from woodcam.inference import knots
from woodcam.inference.observations import gather_observations

OUT = Path(__file__).parent / "pith_pairs_50287.png"


def main():
    warnings.simplefilter("ignore")
    block, info = make_block(50287, 1, "noisy", "realistic", 256)
    obs, exits = gather_observations(block), knots.knot_exits(block)
    # FIT_VERSION 16's order: no pair passes the pith, none shares an exit
    with mock.patch.object(knots, "KNOT_PAIR_MAX_MISS_SHARE", -1.0), \
            mock.patch.object(knots, "KNOT_SHARE_MAX_MISS_MM", -1.0):
        before = knots.fit_knotted_stem(obs, block.size_mm, exits, cones=True)
    after = knots.fit_knotted_stem(obs, block.size_mm, exits, cones=True)
    fields_on_planes(block, {"exits in distance order (v16)": before, "exits paired by the pith (v17)": after}, OUT,
                     f"seed 50287 {info['name']} (six faces, noisy), the stem bent round its knots' cones, "
                     "black = true rings, within 2 mm", label=lambda name, score: f"{name}: {score['matched_2']:.1f} %")


if __name__ == "__main__":
    main()
