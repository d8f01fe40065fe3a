"""Regenerate docs/img/bend_residual_35089.png: cut planes of seed 35089 block 18 (six noisy faces;
one knot 20-56 mm across crosses the block corner to corner), three hypotheses of the default
evidence fit: radial + residual, chosen by FIT_VERSION 14; the stem bent round the knot's cone,
whose faces it misfits; and the same bend with a residual on it, chosen by FIT_VERSION 15.

    python docs/img/make_bend_residual.py
"""

import warnings
from pathlib import Path

from PIL import Image

from woodcam.bench_realistic import BENCH_PIXEL_MM, make_block
from woodcam.inference import fit_block
from woodcam.inference.evaluate import DEFAULT_PLANES, evaluate_fits, plot_planes

OUT = Path(__file__).parent / "bend_residual_35089.png"


def main():
    warnings.simplefilter("ignore")
    block, info = make_block(35089, 18, "noisy", "realistic", 256)
    ev = fit_block(block, baked=False)
    held = {n: v["mean"] for n, v in ev.scores.items()}
    names = {"radial + residual": "radial + residual (v14)", "stem + knot bend": "stem + knot bend",
             "stem + knot bend + residual": "bend + residual (v15)"}
    fields = {label: ev.hypotheses[n] for n, label in names.items()}
    sc = evaluate_fits(block.true_field, fields, block.size_mm, DEFAULT_PLANES, BENCH_PIXEL_MM, keep_lines=True)
    for k, v in sc.items():
        print(f"{k}: {v[0]['matched_1']:.1f} / {v[0]['matched_2']:.1f} % within 1 / 2 mm")
    print(ev.message)
    plot_planes(OUT, {k: v[1] for k, v in sc.items()},
                title=f"seed 35089 {info['name']} (six faces, noisy), black = true rings; held out: "
                      + ", ".join(f"{n} {held[n]:.1f} %" for n in names))
    Image.open(OUT).convert("RGB").quantize(64).save(OUT, optimize=True)


if __name__ == "__main__":
    main()
