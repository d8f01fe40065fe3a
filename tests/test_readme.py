"""The README's quick start runs as written, in order, and its outputs reload (issue 17)."""

from __future__ import annotations

import os
import re
import shlex
import subprocess
import sys
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[1]


def _quick_start() -> list[str]:
    """The ``woodcam ...`` lines of the code block under '## Using it', comments removed."""
    text = (REPO / "README.md").read_text()
    section = text.split("## Using it", 1)[1].split("\n## ", 1)[0]
    block = re.search(r"```\n(.*?)```", section, re.S).group(1)
    return [line.split("  #")[0].strip() for line in block.splitlines()
            if line.startswith("woodcam ")]


def test_the_quick_start_lists_the_main_commands():
    commands = _quick_start()
    assert [c.split()[1] for c in commands][:3] == ["demo", "blocks", "bake"]


@pytest.mark.slow  # runs the demo and every quick-start command (~3-5 min)
def test_the_quick_start_runs_as_written(tmp_path):
    for name in ("cad_examples", "toolpaths"):
        (tmp_path / name).symlink_to(REPO / name)
    env = {**os.environ, "WOODCAM_CACHE_DIR": str(tmp_path / "cache")}
    for command in _quick_start():
        argv = shlex.split(command)
        if argv[1] == "preview" and "--screenshot" not in argv:
            continue  # opens a window: the next line renders the same view off screen
        run = subprocess.run([sys.executable, "-m", "woodcam.cli", *argv[1:]], cwd=tmp_path,
                             env=env, capture_output=True, text=True, timeout=1800)
        assert run.returncode == 0, f"{command}\n{run.stderr[-2000:]}"
    from woodcam.export import load_textured, read_glb_metadata

    glb = tmp_path / "out" / "bowl.glb"
    assert len(load_textured(glb).faces) > 1000
    assert read_glb_metadata(glb)["block"] == "builtin:flat-sawn"
    assert load_textured(tmp_path / "out" / "bowl.obj").visual.uv is not None
    assert (tmp_path / "out" / "bowl.png").is_file() and (tmp_path / "out" / "bowl_texture.png").is_file()
    assert (tmp_path / "out" / "bowl.html").stat().st_size > 1e6
    assert (tmp_path / "out" / "place" / "placements.png").is_file()


# --- every command line the READMEs show is one the CLI takes ----------------------------------

_DOCS = ("README.md", "toolpaths/README.md", "cad_examples/README.md")


def _doc_commands(text: str) -> list[tuple[str, str]]:
    """Every ``woodcam ...`` command of ``text`` as ``(kind, command)``: kind ``block`` for a line
    of a code block (``\\`` continuations joined, ``  #`` comments cut), ``inline`` for a
    backtick span outside code blocks (which may wrap over lines; often a fragment)."""
    found: list[tuple[str, str]] = []
    for i, part in enumerate(re.split(r"(```.*?```)", text, flags=re.S)):
        if i % 2:  # a code block
            joined = re.sub(r"\\\n\s*", " ", part)
            found += [("block", " ".join(line.split("  #")[0].split()))
                      for line in joined.splitlines() if line.strip().startswith("woodcam ")]
        else:
            found += [("inline", " ".join(m.group(1).split()))
                      for m in re.finditer(r"`(?:[A-Z_]+=\S+ )?(woodcam [^`]+)`", part)]
    return found


def _command_problems(kind: str, command: str, parser) -> list[str]:
    """What is wrong with ``command`` for ``parser``: a command or sub-command that does not exist,
    an ``--option`` its command does not have, and for a complete code-block line (no ``...``)
    anything argparse refuses (a required argument left out)."""
    import argparse
    import contextlib
    import io

    def subcommands(p):
        return next((a.choices for a in p._actions if isinstance(a, argparse._SubParsersAction)), {})

    tokens = command.replace("[", " ").replace("]", " ").split()[1:]
    p, path = parser, ["woodcam"]
    while subcommands(p) and tokens and tokens[0] in subcommands(p):
        path.append(tokens.pop(0))
        p = subcommands(p)[path[-1]]
    problems = []
    if subcommands(p) and tokens and not tokens[0].startswith("-"):
        problems.append(f"{' '.join(path)} has no sub-command {tokens[0]!r}")
    options = {s for a in p._actions for s in a.option_strings}
    problems += [f"{' '.join(path)} has no option {t.split('=')[0]}" for t in tokens
                 if t.startswith("--") and t.split("=")[0] not in options]
    if kind == "block" and "..." not in command and not problems:
        err = io.StringIO()
        try:
            with contextlib.redirect_stderr(err), contextlib.redirect_stdout(io.StringIO()):
                parser.parse_args(shlex.split(command)[1:])
        except SystemExit:
            problems.append(err.getvalue().strip().splitlines()[-1])
    return problems


def test_the_checker_catches_a_wrong_command_option_or_missing_argument():
    """The check below is not vacuous: each kind of mistake a README line can make is caught."""
    from woodcam.cli import build_parser

    parser = build_parser()
    text = ("Run `woodcam eval MOKUME --detect`, `woodcam gcode x.nc --tol 0.1 --out o.glb` or\n"
            "`woodcam bake part.py --block\nbuiltin:rift --out p.glb --texels 4`:\n\n```\n"
            "woodcam block show blocks/b --out x.png   # fine\n"
            "woodcam review out/bowl.glb               # no --out\n"
            "woodcam fit BLOCK \\\n    --method radial --out f.npz --face front\n```\n")
    problems = {c: _command_problems(k, c, parser) for k, c in _doc_commands(text)}
    assert problems["woodcam eval MOKUME --detect"] == [
        "woodcam eval has no sub-command 'MOKUME'", "woodcam eval has no option --detect"]
    assert problems["woodcam gcode x.nc --tol 0.1 --out o.glb"] == ["woodcam gcode has no option --tol"]
    assert problems["woodcam bake part.py --block builtin:rift --out p.glb --texels 4"] == [
        "woodcam bake has no option --texels"]
    assert problems["woodcam block show blocks/b --out x.png"] == []
    assert "--out" in problems["woodcam review out/bowl.glb"][0]
    assert problems["woodcam fit BLOCK --method radial --out f.npz --face front"] == [
        "woodcam fit has no option --face"]


def test_every_readme_command_is_one_the_cli_takes():
    """Every ``woodcam`` command the READMEs show names real commands and options of that
    command, and every complete code-block line parses (a user copies them)."""
    from woodcam.cli import build_parser

    parser = build_parser()
    commands = [(doc, kind, command) for doc in _DOCS
                for kind, command in _doc_commands((REPO / doc).read_text())]
    assert len(commands) > 60 and sum(kind == "block" for _, kind, _ in commands) > 15
    wrong = [f"{doc}: {command}: {problem}" for doc, kind, command in commands
             for problem in _command_problems(kind, command, parser)]
    assert not wrong, "\n".join(wrong)


# --- every WOODCAM_* setting the package reads is the README's, and no other --------------------

def _env_problems(readme: str) -> list[str]:
    """The ``WOODCAM_*`` environment variables the package reads (a ``"WOODCAM_..."`` literal, and
    ``WOODCAM_<NAME>`` of each ``MAX_`` limit of :mod:`woodcam.limits`, which ``limit`` reads) that ``readme`` never names, and those
    it names that the package does not read (a variable renamed in the code only)."""
    from woodcam import limits

    code = {name for path in (REPO / "woodcam").rglob("*.py")
            for name in re.findall(r"[\"'](WOODCAM_[A-Z][A-Z_]*[A-Z])[\"']", path.read_text())}
    code |= {f"WOODCAM_{name}" for name in dir(limits) if name.startswith("MAX_")}
    named = set(re.findall(r"WOODCAM_[A-Z][A-Z_]*[A-Z]", readme))
    return ([f"README never names {v}, which woodcam reads" for v in sorted(code - named)]
            + [f"README names {v}, which woodcam does not read" for v in sorted(named - code)])


def test_the_readme_names_every_environment_setting_and_only_those():
    """A setting added to the code, or renamed in it, is named in the README under its name."""
    problems = _env_problems((REPO / "README.md").read_text())
    assert not problems, "\n".join(problems)


# --- every command and option `woodcam ... --help` lists is in the README -----------------------

def _undocumented(readme: str, parser) -> list[str]:
    """Each command of ``parser`` (``block show``) no README section names (as ``woodcam block
    show`` or a backtick span starting ``block show``), and each ``--option`` of a command that
    no section naming that command mentions (an alias of the option does); sections are the
    README's ``##``/``###`` headings."""
    import argparse

    def walk(p, path):
        children = next((a.choices for a in p._actions
                         if isinstance(a, argparse._SubParsersAction)), {})
        if not children:
            yield path, p
        for name, child in children.items():
            yield from walk(child, [*path, name])

    sections = re.split(r"\n(?=#{2,3} )", readme)
    problems = []
    for path, p in walk(parser, []):
        name = " ".join(path)
        naming = re.compile(r"(?:woodcam |`)" + re.escape(name) + r"(?![\w-])")
        mine = [s for s in sections if naming.search(s)]
        if not mine:
            problems.append(f"woodcam {name}: no README section names it")
            continue
        for action in p._actions:
            spellings = [s for s in action.option_strings if s.startswith("--") and s != "--help"]
            if spellings and not any(re.search(re.escape(o) + r"(?![\w-])", s)
                                     for s in mine for o in spellings):
                problems.append(f"woodcam {name} {spellings[0]}: no README section naming "
                                f"'{name}' mentions it")
    return problems


def test_every_command_and_option_of_the_cli_is_in_the_readme():
    """A command or option added to the CLI (or an option renamed) is documented in a README
    section that names its command, not only in ``--help``."""
    from woodcam.cli import build_parser

    problems = _undocumented((REPO / "README.md").read_text(), build_parser())
    assert not problems, "\n".join(problems)


# --- the package docstring's Python example runs as written ----------------------------------------

def _package_example() -> list[str]:
    """The indented code lines under "The pipeline, one name per stage::" of ``woodcam.__doc__``,
    comments cut."""
    import woodcam

    block = woodcam.__doc__.split("::", 1)[1]
    return [line.split("  #")[0].strip() for line in block.splitlines() if line.startswith("    ")]


def test_the_package_docstring_example_runs(tmp_path, monkeypatch):
    """``help(woodcam)`` is where a Python user starts: its four lines run as written (a notebook
    in a folder with bowl.py), the window of ``preview`` aside (it gets the GLB written). ~7 s:
    it carves and bakes the bowl at 10 texels/mm."""
    import woodcam

    lines = _package_example()
    assert len(lines) == 4 and lines[0].startswith("stock = open_stock(")
    (tmp_path / "bowl.py").symlink_to(REPO / "cad_examples" / "bowl.py")
    monkeypatch.chdir(tmp_path)
    shown = []
    monkeypatch.setattr(woodcam, "preview", lambda path, **kw: shown.append((path, kw)))
    scope = {name: getattr(woodcam, name) for name in woodcam.__all__}
    for line in lines:
        exec(line, scope)  # noqa: S102 - the docstring's own code
    assert len(woodcam.load_textured(tmp_path / "bowl.glb").faces) > 1000
    assert shown and shown[0][0] == "bowl.glb" and shown[0][1]["size_mm"] == (100.0, 80.0, 50.0)
