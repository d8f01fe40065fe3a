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


def fields_on_planes(block, fields: dict, out: Path, title: str, label=lambda name, score: name) -> None:
    """Draw the cut planes of ``fields`` (row name -> field) of ``block`` against its true rings
    into ``out`` (64 colours), printing each one's share within 1 / 2 mm; ``label(name, score)``
    makes a row's label from its name and :func:`evaluate_fits`'s scores."""
    sc = evaluate_fits(block.true_field, fields, block.size_mm, DEFAULT_PLANES, BENCH_PIXEL_MM, keep_lines=True)
    for k, v in sc.items():
        print(f"{k}: {v[0]['matched_1']:.1f} / {v[0]['matched_2']:.1f} % within 1 / 2 mm")
    plot_planes(out, {label(k, v[0]): v[1] for k, v in sc.items()}, title=title)
    Image.open(out).convert("RGB").quantize(64).save(out, optimize=True)


def hypotheses_on_planes(seed: int, index: int, labels: dict, out: Path, title) -> None:
    """Fit benchmark block ``(seed, index)`` (six noisy faces, the default evidence fit) and draw
    the cut planes of the hypotheses ``labels`` (name -> row label) against the true rings;
    ``title(info, held)`` makes the title from the block's info and the held-out scores."""
    warnings.simplefilter("ignore")
    block, info = make_block(seed, index, "noisy", "realistic", 256)
    ev = fit_block(block, baked=False)
    held = {n: v["mean"] for n, v in ev.scores.items()}
    print(ev.message)
    fields_on_planes(block, {label: ev.hypotheses[n] for n, label in labels.items()}, out, title(info, held))


def main():
    hypotheses_on_planes(63311, 2, {"stem": "stem (before)", "stem + knot bend": "bend (now)"}, OUT,
                         lambda info, held: f"dev seed 63311 {info['name']} (six faces, noisy), black = true rings: "
                         f"the plain stem, chosen before (held out {held['stem']:.1f} %), and the stem + knot bend, "
                         f"chosen now (held out {held['stem + knot bend']:.1f} %)")


if __name__ == "__main__":
    main()
