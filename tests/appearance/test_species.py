"""Species presets: at least 12 with a cited source, each renders within the colour contract
(finite, in [0, 1], latewood darker than earlywood where the field says) and looks distinct."""

import itertools
import re

import numpy as np
import pytest

from woodcam.appearance import SPECIES, ColorMapAppearance, Wood
from woodcam.appearance.colormap import ISCC_NBS_SRGB
from woodcam.fields import LogFrame
from woodcam.fields.radial import RadialScalingField

CITED = {k: s for k, s in SPECIES.items() if not s.source.startswith("legacy")}
FIELD = RadialScalingField(LogFrame((-40.0, 20.0, 0.0), (0, 0, 1)), ring_width_mm=3.0)


def test_at_least_twelve_presets_with_a_quoted_source():
    assert len(CITED) >= 12, sorted(CITED)
    for name, s in CITED.items():
        assert s.name == name
        assert re.search(r"'[^']+'", s.source), f"{name}: the source quotes no description"
        assert re.search(r"https?://|Handbook|Press", s.source), f"{name}: no publication"
    assert all(s.source for s in SPECIES.values())  # the legacy six say they have none


def test_cited_colours_are_the_iscc_nbs_centroids_their_source_names():
    """No number of a cited preset is made up: each colour is the centroid of a named colour."""
    for name, s in CITED.items():
        early, late = re.search(r"ISCC-NBS '([^']+)' / '([^']+)'", s.source).groups()
        assert s.earlywood_rgb == pytest.approx(np.array(ISCC_NBS_SRGB[early]) / 255), name
        assert s.latewood_rgb == pytest.approx(np.array(ISCC_NBS_SRGB[late]) / 255), name


def _render(name, rng):
    wood = Wood(FIELD, ColorMapAppearance(name))
    p = rng.uniform(0, 50, (20000, 3))
    side = wood.color(p, np.tile([0.0, -1, 0], (len(p), 1)))
    return wood.arf(p), side


@pytest.mark.parametrize("name", sorted(SPECIES))
def test_every_preset_renders_within_the_colour_contract(name, rng):
    a, c = _render(name, rng)
    assert c.shape == (len(a), 3) and np.isfinite(c).all()
    assert c.min() >= 0.0 and c.max() <= 1.0
    s = SPECIES[name]
    luma = c.mean(1)
    assert luma[a > 0.9].mean() < luma[a < 0.2].mean()  # latewood darker, where the field says
    # earlywood side grain is the preset's earlywood colour, up to pores and streaks
    assert np.median(c[a < 0.2], 0) == pytest.approx(s.earlywood_rgb, abs=0.08)


def test_presets_are_distinct():
    """Rendered earlywood and latewood bands (side grain) tell every pair of presets apart."""
    bands = {}
    for n in SPECIES:
        a, c = _render(n, np.random.default_rng(0))
        bands[n] = np.concatenate([np.median(c[a < 0.2], 0), np.median(c[a > 0.95], 0)])
    close = [(a, b) for a, b in itertools.combinations(bands, 2)
             if np.abs(bands[a] - bands[b]).max() < 0.04]
    assert not close, close


def test_the_species_help_lists_every_preset():
    from woodcam.cli.options import SPECIES_HELP

    listed = set(re.findall(r"[a-z]+(?:-[a-z]+)*", SPECIES_HELP.split(":", 1)[1]))
    assert set(SPECIES) <= listed, set(SPECIES) - listed


def test_woodcam_species_lists_every_preset_with_its_source(capsys):
    from woodcam.cli import main

    assert main(["species"]) == 0
    lines = capsys.readouterr().out.splitlines()
    assert [line.split()[0] for line in lines] == list(SPECIES)
    walnut = next(line for line in lines if line.startswith("black-walnut "))
    assert "earlywood #ad7c63 latewood #442112" in walnut  # ISCC-NBS light / dark brown
    assert "Wood Handbook" in walnut


@pytest.mark.parametrize("argv", [["bake", "p.stl", "--block", "builtin:flat-sawn", "--out", "x.glb"],
                                  ["log", "render", "--real", "--out", "d"]])
def test_an_unknown_species_is_a_usage_error(argv, capsys):
    """Sweep h5 item 13: --species teak was refused by the library after parsing, with exit 1."""
    from woodcam.cli import main
    from woodcam.cli.options import CITED_SPECIES, LEGACY_SPECIES

    assert set(CITED_SPECIES + LEGACY_SPECIES) == set(SPECIES)  # the CLI's list is the library's
    with pytest.raises(SystemExit) as code:
        main([*argv, "--species", "teak"])
    assert code.value.code == 2
    assert "argument --species: 'teak' is not a colour preset; choose one of red-oak" in capsys.readouterr().err
