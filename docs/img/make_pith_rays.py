"""Regenerate docs/img/pith_rays_63311.png: cut planes of dev seed 63311 block 13 (three noisy
faces, front, top and left; one knot, seen at the left face only, rising 18 degrees), the stem
fitted with that knot marking its place only (FIT_VERSION 17: a one-exit strand is a guess and
bends nothing), the ray from the pith through the exit across the stem (rise 0) and the ray at
the rise the rings choose (FIT_VERSION 18), against the true rings.

    python docs/img/make_pith_rays.py
"""

import warnings
from pathlib import Path
from unittest import mock

from make_bend_takes_place import fields_on_planes  # (run from docs/img: its folder is on the path)

from woodcam.bench_realistic import FACE_SETS, make_block
from woodcam.inference import knots
from woodcam.inference.observations import gather_observations

OUT = Path(__file__).parent / "pith_rays_63311.png"


def main():
    warnings.simplefilter("ignore")
    block, info = make_block(63311, 13, "noisy", "realistic", 256)
    faces = FACE_SETS["three"]
    obs, exits = gather_observations(block, faces), knots.knot_exits(block, faces)
    fits = {}
    for name, rises in (("one exit marks its knot only (v17)", lambda *a: {}),
                        ("ray from the pith, rise 0", lambda ex, *a: dict.fromkeys(range(len(ex)), 0.0)),
                        ("ray at the rise the rings choose (v18)", knots._ray_rises)):
        with mock.patch.object(knots, "_ray_rises", rises):
            fits[name] = knots.fit_knotted_stem(obs, block.size_mm, exits, cones=True)
    fields_on_planes(block, fits, OUT, f"dev seed 63311 {info['name']} (front, top, left; noisy), the stem bent round "
                     "its knot, black = true rings, within 2 mm",
                     label=lambda name, score: f"{name}: {score['matched_2']:.1f} %")


if __name__ == "__main__":
    main()
