"""Regenerate docs/img/bend_takes_place_63311.png: cut planes of dev seed 63311 block 2 (six noisy
faces), the two hypotheses of the default evidence fit that FIT_VERSION 13 decides between: the
plain stem, which wins the held-out vote (84.6 against 72.3 %) and was chosen before, and the stem
bent round the knot whose exits the masks show on the left and right faces, which takes the
stem's place now.

    python docs/img/make_bend_takes_place.py
"""

import warnings
from pathlib import Path

from PIL import Image

from woodcam.bench_realistic import BENCH_PIXEL_MM, make_block
from woodcam.inference import fit_block
from woodcam.inference.evaluate import DEFAULT_PLANES, evaluate_fits, plot_planes

OUT = Path(__file__).parent / "bend_takes_place_63311.png"


def main():
    warnings.simplefilter("ignore")
    block, info = make_block(63311, 2, "noisy", "realistic", 256)
    ev = fit_block(block, baked=False)
    held = {n: v["mean"] for n, v in ev.scores.items()}
    fields = {"stem (before)": ev.hypotheses["stem"], "bend (now)": ev.hypotheses["stem + knot bend"]}
    sc = evaluate_fits(block.true_field, fields, block.size_mm, DEFAULT_PLANES, BENCH_PIXEL_MM, keep_lines=True)
    for k, v in sc.items():
        print(f"{k}: {v[0]['matched_1']:.1f} / {v[0]['matched_2']:.1f} % within 1 / 2 mm")
    print(ev.message)
    plot_planes(OUT, {k: v[1] for k, v in sc.items()},
                title=f"dev seed 63311 {info['name']} (six faces, noisy), black = true rings: the plain stem, "
                      f"chosen before (held out {held['stem']:.1f} %), and the stem + knot bend, chosen now "
                      f"(held out {held['stem + knot bend']:.1f} %)")
    Image.open(OUT).convert("RGB").quantize(64).save(OUT, optimize=True)


if __name__ == "__main__":
    main()
