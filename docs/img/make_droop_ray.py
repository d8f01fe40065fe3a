"""Regenerate docs/img/droop_ray_7777.png: cut planes of dev seed 7777 block 10 (six noisy faces;
a knot drooping 20 degrees leaves by a bottom-right-back corner, its ray across the stem would
run along the bottom face) against the true rings: radial + residual, which FIT_VERSION 18
chose (the knot's rise was never searched, so its bend had nothing to hold the rings there),
and the bend with its residual, which FIT_VERSION 19 chooses (the rise searched wherever some
rise has a ray), both hypotheses of one default evidence fit.

    python docs/img/make_droop_ray.py
"""

from pathlib import Path

from make_bend_takes_place import hypotheses_on_planes  # (run from docs/img: its folder is on the path)

OUT = Path(__file__).parent / "droop_ray_7777.png"


def main():
    hypotheses_on_planes(7777, 10, {"radial + residual": "radial + residual (chosen by v18)",
                                    "stem + knot bend + residual": "bend + residual (chosen by v19)"}, OUT,
                         lambda info, held: f"dev seed 7777 {info['name']} (six faces, noisy), black = true rings; "
                         f"held out {held['radial + residual']:.1f} / {held['stem + knot bend + residual']:.1f} %")


if __name__ == "__main__":
    main()
