"""Regenerate docs/img/bend_residual_35089.png: cut planes of seed 35089 block 18 (six noisy faces;
one knot 20-56 mm across crosses the block corner to corner), three hypotheses of the default
evidence fit: radial + residual, chosen by FIT_VERSION 14; the stem bent round the knot's cone,
whose faces it misfits; and the same bend with a residual on it, chosen by FIT_VERSION 15.

    python docs/img/make_bend_residual.py
"""

from pathlib import Path

from make_bend_takes_place import hypotheses_on_planes  # (run from docs/img: its folder is on the path)

OUT = Path(__file__).parent / "bend_residual_35089.png"
NAMES = {"radial + residual": "radial + residual (v14)", "stem + knot bend": "stem + knot bend",
         "stem + knot bend + residual": "bend + residual (v15)"}


def main():
    hypotheses_on_planes(35089, 18, NAMES, OUT,
                         lambda info, held: f"seed 35089 {info['name']} (six faces, noisy), black = true rings; "
                         "held out: " + ", ".join(f"{n} {held[n]:.1f} %" for n in NAMES))


if __name__ == "__main__":
    main()
