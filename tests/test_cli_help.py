"""Every option of every command states its default, and every numeric option its unit."""

from __future__ import annotations

import argparse
import re

from woodcam.cli import _walk_options, build_parser

#: Words that name a unit or what a number counts.
UNITS = re.compile(
    r"(\b(mm|mm\^3|deg|degrees?|px|pixels?|texels?|years?|seconds?|s|%|MiB|GiB|voxels?|"
    r"triangles?|blocks?|steps?|epochs?|workers?|threads?|faces?|points?|rings?|placements?|"
    r"cells?|nodes?|samples?|patches|sheets?|dpi|inch(es)?|times|per mm|in \[|fraction|ratio|"
    r"unitless|no unit)\b|--units\b)", re.I)
#: Numbers that are dimensionless by nature (named by the option itself).
DIMENSIONLESS = {"--seed", "--k-stem", "--k-knot", "--quality", "--shape", "--eccentricity",
                 "--until-line",  # a line number
                 "--cut-normal", "--up"}  # directions: unit-normalised
#: Option names that carry their unit (--px-per-mm, --size-mm, --connect-timeout-s).
NAMED_UNIT = re.compile(r"-(mm|per-mm|s|mb|deg|px)$")


def test_every_option_states_its_default():
    missing = []
    for path, action in _walk_options(build_parser()):
        flag = isinstance(action, (argparse._StoreTrueAction, argparse._StoreFalseAction,
                                   argparse._StoreConstAction, argparse._CountAction))
        if not (flag or action.required or "default" in (action.help or "").lower()):
            missing.append(f"{' '.join(path)} {action.option_strings[-1]}")
    assert not missing, missing


def _numeric(action) -> bool:
    """A number, or numbers (a vector X,Y,Z, a size WxDxH, nargs=3 floats)."""
    name = getattr(action.type, "__qualname__", "")
    return action.type in (int, float) or name.startswith(("vector_type.", "sizes_type."))


def _outside_default(text: str) -> str:
    """The help without its default clause: a unit named only in the default's example ('the
    board through the most knots at 60 mm') does not say which unit the value is read in."""
    text = " ".join(text.split())
    text = re.sub(r"\(default[^()]*(\([^()]*\)[^()]*)*\)", "", text)
    return re.sub(r"default[^;)]*", "", text, flags=re.I)


def test_every_numeric_option_names_its_unit():
    """``log render --board`` (height, azimuth and offset) named no unit but in its default's
    example (60 mm); vectors and sizes were not checked at all."""
    missing = [f"{' '.join(path)} {a.option_strings[-1]}: {a.help!r}"
               for path, a in _walk_options(build_parser())
               if _numeric(a) and a.option_strings[-1] not in DIMENSIONLESS
               and not UNITS.search(_outside_default(a.help or ""))
               and not NAMED_UNIT.search(a.option_strings[-1])]
    assert not missing, missing


def test_every_numeric_option_says_what_its_default_is():
    """'--epochs ... (default: not set)' (bake, demo, gcode, eval appearance) said nothing of
    the epochs trained without it (the --quality's); an option left unset by default says what
    happens then."""
    unsaid = [f"{' '.join(path)} {a.option_strings[-1]}: {a.help!r}"
              for path, a in _walk_options(build_parser())
              if _numeric(a) and not a.required and "(default: not set)" in (a.help or "")]
    assert not unsaid, unsaid


def test_the_epochs_default_said_is_the_quality_presets():
    from woodcam.appearance.translation import QUALITY_SPECS
    from woodcam.cli.options import QUALITY_EPOCHS_HELP

    assert QUALITY_EPOCHS_HELP == ", ".join(f"{s.epochs} {q}" for q, s in QUALITY_SPECS.items())


def _sub_commands(parser):
    for action in parser._actions:
        if isinstance(action, argparse._SubParsersAction):
            for name, sp in action.choices.items():
                yield name, sp
                yield from _sub_commands(sp)


def test_every_command_says_what_it_does():
    """``block show --help`` (and nine others) went from usage straight to the arguments."""
    commands = list(_sub_commands(build_parser()))
    assert {"show", "synth", "render", "info", "species", "rings"} <= {n for n, _ in commands}
    silent = [name for name, sp in commands if not (sp.description or "").strip()]
    assert not silent, silent


def test_a_block_spec_read_in_units_says_so():
    """``bake --help`` said 'builtin:NAME[:WxDxH] (mm)' under --block and 'unit of a block spec's
    WxDxH' under --units: with --units inch the size is in inches."""
    from woodcam.cli.options import LENGTH_OPTIONS

    wrong = [f"{' '.join(path)} {a.option_strings[-1]}: {a.help!r}"
             for path, a in _walk_options(build_parser())
             if path and LENGTH_OPTIONS.get((path[0], a.dest)) == "spec"
             and ("WxDxH] (mm)" in (a.help or "") or "--units" not in (a.help or ""))]
    assert not wrong, wrong


def test_block_synth_help_states_the_ranges_of_count_seed_and_face_px():
    """'block synth --help' said 'number of blocks' and 'random seed', and the ranges came out
    only in the error ('--count must be in [1, 1e+06]; got 0')."""
    helps = {a.option_strings[-1]: " ".join((a.help or "").split())
             for path, a in _walk_options(build_parser()) if path[-2:] == ["block", "synth"]}
    assert "in [1, 100000]" in helps["--count"], helps["--count"]
    assert "in [0, 4294967295]" in helps["--seed"], helps["--seed"]
    assert "in [16, 16384]" in helps["--face-px"], helps["--face-px"]


def test_every_numeric_option_states_the_range_it_is_checked_against():
    """'block synth --count' said 'in [1, 1e+06]', but 'bench run --blocks', 'review --voxels'
    (a user's '--voxels 16' was refused: 'in [1000, 8e+06]'), 'place --candidates' and 60 more
    said no range: a user learnt it from the refusal. Each numeric option's help states its
    RANGES entry (a length in --units in mm, the unit it is checked in), once."""
    from woodcam.cli.options import option_bounds, option_range

    unsaid = []
    for path, a in _walk_options(build_parser()):
        if a.type not in (int, float) or option_bounds(a.dest, path[0]) is None:
            continue
        span = option_range(a.dest, path[0])[len("in "):]
        text = " ".join((a.help or "").split())
        if text.count(span) != 1:
            unsaid.append(f"{' '.join(path)} {a.option_strings[-1]}: {text!r} lacks {span!r}")
    assert not unsaid, unsaid


def test_place_help_says_what_the_terms_are_and_which_way_is_better():
    """'woodcam place' printed a table of score, knots, pith, end and runout, and its help said
    neither that each is a share in [0, 1], nor that lower is better, nor how the score weighs
    them: a user could not tell the best row from the worst. The weights and the pith's years
    said are the ones used."""
    from woodcam.advise import DEFAULT_WEIGHTS, PITH_YEARS

    place = dict(_sub_commands(build_parser()))["place"]
    text = " ".join(place.description.split())
    w = DEFAULT_WEIGHTS
    assert (f"score = {w['knots']:g} knots + {w['pith']:g} pith + {w['end_grain']:g} end + "
            f"{w['runout']:g} runout, lower is better") in text, text
    assert "Each term is a share in [0, 1], lower is better" in text
    assert f"within {PITH_YEARS:g} years of the pith" in text


def test_the_part_argument_lists_every_suffix_read():
    """'bake --help' and 'place --help' listed .step and .glb, not .stp (a common STEP name)
    nor .gltf, both read: the help lists every suffix load_part reads."""
    from woodcam.cad.parts import SUPPORTED_SUFFIXES

    commands = dict(_sub_commands(build_parser()))
    for name in ("bake", "place"):
        part = next(a for a in commands[name]._actions if a.dest == "part")
        missing = [s for s in SUPPORTED_SUFFIXES if not re.search(re.escape(s) + r"\b", part.help)]
        assert not missing, (name, part.help, missing)


def test_epochs_shows_n_as_the_other_counts_do():
    """``bake --epochs`` (and demo's, gcode's, eval appearance's) showed ``--epochs EPOCHS``
    where the other counts show ``N`` (``--finetune-epochs N``, ``--max-triangles N``)."""
    shown = {(" ".join(path), a.option_strings[-1]): a.metavar for path, a in _walk_options(build_parser())
             if a.option_strings[-1] in ("--epochs", "--finetune-epochs")}
    assert len(shown) >= 5 and set(shown.values()) == {"N"}, shown


def test_every_int_option_shows_a_metavar_as_the_counts_do():
    """``--count COUNT``, ``--seed SEED``, ``--face-px FACE_PX``, ``--crack-years CRACK_YEARS``
    ... (ten options) showed argparse's upper-cased name where the other counts show ``N`` (a
    size in pixels ``PX``): every int option has a metavar of its own, and an option has the same
    one in every command."""
    import collections

    shown = collections.defaultdict(dict)
    bare = []
    for path, a in _walk_options(build_parser()):
        if a.type is int:
            flag = a.option_strings[-1]
            shown[flag][" ".join(path)] = a.metavar
            if a.metavar is None:
                bare.append(f"{' '.join(path)} {flag}")
    assert not bare, bare
    assert not {f: m for f, m in shown.items() if len(set(m.values())) > 1}, dict(shown)
    assert {shown[f][c] for f in ("--count", "--seed", "--zoom", "--crack-years") for c in shown[f]} == {"N"}
    assert set(shown["--face-px"].values()) == {"PX"}
