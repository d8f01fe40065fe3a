"""The RS274/NGC language against LinuxCNC's documented semantics (LinuxCNC 2.9 manual,
"G-code overview" and "O codes"; the expected numbers are the documented results)."""

from __future__ import annotations

import re

import pytest

from woodcam.errors import WoodcamError
from woodcam.toolpath import GcodeError, read_gcode
from woodcam.toolpath.interpreter import MAX_CALL_DEPTH, Interpreter


def _ends(text, **kw):
    """End points of the canonical moves of ``text`` started at the origin."""
    moves, _ = Interpreter(text, start_mm=(0, 0, 0), **kw).run()
    return [m[2] for m in moves]


def _x(expr):
    return _ends(f"G0 X[{expr}] Y1\nM2\n")[0][0]


def test_end_of_line_assignment_rule():
    # manual: "#3 = 15 ... #3 = 6 G1 X#3" moves to X15, and #3 is 6 afterwards
    ends = _ends("#3 = 15\n#3 = 6 G0 X#3\nG0 Y#3\n#1=1 #2=[#1+1]\nG0 Z#2\nM2\n")
    assert ends[0][0] == 15 and ends[1][1] == 6
    assert ends[2][2] == 1  # #2 = [#1 + 1] read the old #1 (0) on the same line


@pytest.mark.parametrize("expr, value", [
    ("atan[1]/[-1]", 135.0),          # the manual's example: two-argument arctangent
    ("2 ** 3 ** 2", 64.0),            # left to right
    ("1 + 2 * 3 ** 2", 19.0),         # ** over * over +
    ("10 - 4 - 3", 3.0),
    ("3 eq 3 + 4", 0.0),              # + binds tighter than eq
    ("1 eq 1.00001", 1.0),            # eq within LinuxCNC's 1e-4
    ("[1 lt 2] and [3 ge 3]", 1.0),
    ("0 or 0", 0.0), ("3 xor 0", 1.0), ("3 xor 4", 0.0), ("2 ne 2", 0.0), ("2 gt 1", 1.0),
    ("-7 mod 3", 2.0), ("10 mod -3", 1.0),   # mod is never negative (LinuxCNC)
    ("round[-2.5]", -3.0), ("round[2.5]", 3.0), ("fix[-2.5]", -3.0), ("fup[-2.5]", -2.0),
    ("sqrt[16] + abs[-2]", 6.0), ("exp[ln[7]]", 7.0), ("sin[30] * 2", 1.0),
    ("acos[0]", 90.0), ("asin[1]", 90.0), ("tan[45]", 1.0), ("cos[180]", -1.0),
    ("-[2 * 3]", -6.0), ("- - 2", 2.0),
])
def test_expressions(expr, value):
    assert _x(expr) == pytest.approx(value, abs=1e-12)


@pytest.mark.parametrize("expr, rule", [
    ("1 / 0", "division by zero"), ("sqrt[-1]", "negative"), ("ln[0]", "logarithm"),
    ("acos[2]", "outside"), ("[-8] ** 0.5", "non-integer power"), ("1 mod 0", "mod by zero"),
    ("atan[1]", "two arguments"), ("1 +", "bad value"), ("1 % 2", "operator"),
])
def test_expression_errors(expr, rule):
    with pytest.raises(GcodeError, match=rule):
        _x(expr)


def test_parameters_numbered_named_global_indirect():
    text = ("#<a> = 1\n#<_bb> = 2\n#10 = 20\n#20 = 7\n#<Spaced Name> = 4\n"
            "o5 sub\n#<a> = 100\n#<_bb> = 30\n#1 = 55\nG0 X#<a> Y#<_bb> Z#1\no5 endsub\n"
            "G0 X#<a> Y#<_bb> Z5\no5 call [1] [2]\nG0 X#<a> Y#<_bb> Z#1\n"
            "G0 X##10 Y#[10 + 10] Z#<spacedname>\nM2\n")
    ends = _ends(text)
    assert ends[0] == (1, 2, 5)
    assert ends[1] == (100, 30, 55)            # the sub sees its own #<a>, #1 = 55 local
    assert ends[2] == (1, 30, 0)               # locals restored, global kept, #1 back to 0
    assert ends[3] == (7, 7, 4)                # ##10 = #20; names lose case and spaces


def test_named_parameter_errors():
    with pytest.raises(GcodeError, match=r"#<nope> not defined"):
        _ends("G0 X#<nope>\nM2\n")
    with pytest.raises(GcodeError, match=r"read-only"):
        _ends("#<_x> = 3\nM2\n")
    with pytest.raises(GcodeError, match=r"out of range"):
        _ends("G0 X#6000\nM2\n")
    assert _ends("G0 X5\nG0 Y#<_x>\nM2\n")[1] == (5, 5, 0)  # system parameter: current X


def _read(names, setup=""):
    """The values of the predefined parameters ``names`` after the lines ``setup``."""
    reads = "".join(f"#{100 + i} = #<{n}>\n" for i, n in enumerate(names))
    moves = "".join(f"G0 X[1000 + #{100 + i}]\nG0 X0\n" for i in range(len(names)))
    ends = _ends(setup + reads + "G21 G90 G80\n" + moves + "M2\n")
    return [e[0] - 1000 for e in ends if e[0] > 500]


def test_predefined_named_parameters_read_as_in_linuxcnc():
    """LinuxCNC 2.9's predefined named parameters (its values, measured; all of them against
    its interpreter in 52 states in test_linuxcnc_oracle.py): woodcam read only #<_x>,
    #<_metric> ... and refused #<_call_level>, #<_motion_mode>, #<_vmajor> ... as 'not
    defined; assign it' (a program cannot assign them); #<_coord_system> read 600-620 for
    G59.1-G59.3 (591-593)."""
    names = ["_task", "_call_level", "_remap_level", "_motion_mode", "_plane", "_ccomp",
             "_units_per_minute", "_retract_r_plane", "_retract_old_z", "_spindle_on",
             "_spindle_cw", "_mist", "_flood", "_feed_override", "_speed_override",
             "_adaptive_feed", "_feed_hold", "_ijk_absolute_mode", "_tool_offset",
             "_coord_system", "_vmajor"]
    assert _read(names) == pytest.approx(
        [1, 0, 0, 800, 170, 400, 1, 1, 0, 0, 0, 0, 0, 1, 1, 0, 1, 0, 0, 540, 2.9])
    after = ("G98 G18 G90.1 G43.1 Z1 G59.1\nS100 M4\nM7\nM50 P0\nM52\nM53 P0\n"
             "G1 X1 F100\n")
    assert _read(names, after) == pytest.approx(
        [1, 0, 0, 10, 180, 400, 1, 0, 1, 1, 0, 1, 0, 0, 1, 1, 0, 1, 1, 591, 2.9])
    assert _read(["_spindle_cw", "_mist", "_flood", "_feed_override", "_speed_override"],
                 "S1 M3\nM8\nM9\nM49\n") == [1, 0, 0, 0, 0]
    assert _read(["_motion_mode"], "G81 X1 Y1 Z-1 R2 F9\n") == [810]
    # the call level inside a subroutine, two deep, and in an M98 subprogram
    assert _ends("o1 sub\nG0 X#<_call_level>\no2 call\no1 endsub\no2 sub\n"
                 "G0 X#<_call_level>\no2 endsub\no1 call\nM98 P5\nM30\nO5\n"
                 "G0 X[#<_call_level> + 4]\nM99\n") == [(1, 0, 0), (2, 0, 0), (5, 0, 0)]
    # what the machine knows and woodcam does not is refused with the reason
    for name, why in (("_current_pocket", "the tool changer pocket of the loaded tool"),
                      ("_vminor", "the patch release"),
                      ("_ini[traj]linear_units", "INI file value"),
                      ("_hal[motion.spindle-speed-out]", "HAL pin")):
        with pytest.raises(GcodeError, match=rf"#<{re.escape(name)}> .*{why}.*woodcam "
                                             "cannot know"):
            _ends(f"G0 X#<{name}>\nM2\n")
    for name in ("_task", "_vmajor", "_motion_mode", "_current_pocket"):  # read-only, as LinuxCNC
        with pytest.raises(GcodeError, match=rf"#<{name}> is a read-only predefined"):
            _ends(f"#<{name}> = 3\nM2\n")


#: EXISTS[] of predefined, unset, assigned, sub-local and INI/HAL names, one move each (Y = n).
EXISTS_PROGRAM = (
    "".join(f"G0 X[EXISTS[#<{n}>]] Y{i}\n" for i, n in enumerate(
        ["_x", "_task", "_vminor", "_current_pocket", "_value", "_value_returned",
         "_motion_mode", "_foo"], 1))
    + "#<_foo> = 2\nG0 X[EXISTS[#<_foo>]] Y9\nG0 X[EXISTS[#<a>]] Y10\n#<a> = 1\n"
    "G0 X[EXISTS[#<a>]] Y11\no1 sub\nG0 X[EXISTS[#<a>]] Y12\n"
    "G0 X[EXISTS[#<_call_level>]] Y13\no1 endsub\no1 call\n"
    "G0 X[EXISTS[#<_ini[traj]linear_units>]] Y14\nG0 X[EXISTS[#<_hal[x.y]>]] Y15\nM2\n")


def test_exists_is_1_for_the_predefined_parameters_as_in_linuxcnc():
    """EXISTS[#<_task>], EXISTS[#<_x>], EXISTS[#<_value>] ... read 0 (only names a program
    assigned counted), where LinuxCNC defines every predefined parameter, those woodcam cannot
    read too (the same program against LinuxCNC in test_linuxcnc_oracle.py)."""
    assert [e[0] for e in _ends(EXISTS_PROGRAM)] == [1, 1, 1, 1, 1, 1, 1, 0, 1, 0, 1, 0, 1,
                                                     0, 0]


def test_nested_calls_return_values_and_recursion_limit():
    text = ("o<sq> sub\no<sq> return [#1 * #1]\no<sq> endsub\n"
            "o<sum> sub\no<sq> call [#1]\n#<s> = #<_value>\no<sq> call [#2]\n"
            "o<sum> return [#<s> + #<_value>]\no<sum> endsub\n"
            "o<sum> call [3] [4]\nG0 X#<_value>\no<sq> call [2]\nG0 Y#<_value>\nM2\n")
    ends = _ends(text)
    assert ends[0][0] == 25 and ends[1][1] == 4
    # a sub that ends without a value resets #<_value> to 0 (LinuxCNC)
    assert _ends("o2 sub\no2 return [9]\no2 endsub\no1 sub\no1 endsub\no2 call\no1 call\n"
                 "G0 X[#<_value> + 1]\nM2\n")[0][0] == 1
    deep = "o1 sub\no2 if [#1 lt {n}]\no1 call [#1 + 1]\no2 endif\nG0 X#1\no1 endsub\n" \
           "o1 call [1]\nM2\n"
    assert len(_ends(deep.format(n=MAX_CALL_DEPTH))) == MAX_CALL_DEPTH
    with pytest.raises(GcodeError, match="nested subroutine calls") as e:
        _ends(deep.format(n=MAX_CALL_DEPTH + 1))
    assert e.value.line == 3


def test_endsub_with_a_value_returns_it_as_linuxcnc():
    """``o1 endsub [5]`` returns 5 as ``o1 return [5]`` does (woodcam read a value only on
    return: #<_value> read 0); #<_value_returned> reads 1 after a value, 0 before any call and
    after a sub without one; LinuxCNC reads a definition's endsub value as it passes over it;
    both are read-only. Each case agrees with LinuxCNC (test_linuxcnc_oracle)."""
    read = "G0 X#<_value> Y#<_value_returned> Z3\n"
    assert _ends("o1 sub\no1 endsub [#1 * 2]\no1 call [3.5]\n" + read + "M2\n") == [(7, 1, 3)]
    assert _ends("o1 sub\n#<r> = [#1 + 1]\no1 endsub [#<r>]\no1 call [4]\n" + read
                 + "M2\n") == [(5, 1, 3)]
    assert _ends(read + "M2\n") == [(0, 0, 3)]
    assert _ends("o1 sub\no1 endsub [5]\no2 sub\no2 endsub\no1 call\no2 call\n" + read
                 + "M2\n") == [(0, 0, 3)]
    assert _ends("G0 X4\no1 sub\no1 endsub [#<_x> + 1]\n" + read + "M2\n")[-1] == (5, 1, 3)
    assert _ends("o1 sub\no1 return [6]\no1 endsub\n" + read + "M2\n") == [(0, 0, 3)]
    with pytest.raises(GcodeError, match=r"line 3: '#<_value>': o1 endsub on line 2 set "
                       r"#<_value> where its subroutine is defined.*#<r> has no value"):
        _ends("o1 sub\no1 endsub [#<r>]\n" + read + "M2\n")
    # an M99 return sets #<_value> to 0 as LinuxCNC does, the unreadable value gone with it
    assert _ends("o1 sub\no1 endsub [#<r>]\nM98 P100\nG0 X[#<_value> + 1]\nM30\nO100\nM99\n"
                 ) == [(1, 0, 0)]
    for name in ("_value", "_value_returned"):
        with pytest.raises(GcodeError, match=f"#<{name}> is a read-only"):
            _ends(f"#<{name}> = 3\nM2\n")
    with pytest.raises(GcodeError, match=r"line 2: 'o1 endsub5': text after o1 endsub \(LinuxCNC: "
                       r"'Unexpected character after O-word'\)"):
        _ends("o1 sub\no1 endsub 5\no1 call\nM2\n")
    with pytest.raises(GcodeError, match="division by zero"):
        _ends("o1 sub\no1 endsub [1/0]\nM2\n")


def test_loops_if_while_do_repeat_break_continue():
    text = ("#1 = 0\no1 while [#1 lt 20]\n#1 = [#1 + 1]\no2 if [[#1 mod 3] eq 0]\n"
            "o1 continue\no2 endif\no3 if [#1 gt 8]\no1 break\no3 endif\nG0 X#1\n"
            "o1 endwhile\no4 repeat [3]\nG0 Y[#1 + 1]\n#1 = [#1 + 1]\no4 endrepeat\n"
            "#2 = 0\no5 do\n#2 = [#2 + 2]\nG0 Z#2\no5 while [#2 lt 0]\n"
            "o6 if [#1 eq 0]\nG0 X100\no6 elseif [#1 eq 13]\nG0 X200\no6 else\nG0 X300\n"
            "o6 endif\nM2\n")
    ends = _ends(text)
    assert [e[0] for e in ends[:6]] == [1, 2, 4, 5, 7, 8]   # 3, 6, 9 skipped; break at 10
    assert [e[1] for e in ends[6:9]] == [11, 12, 13]        # repeat 3 times
    assert ends[9][2] == 2                                  # do ... while runs once
    assert ends[10][0] == 200                               # elseif taken


def test_endless_loop_is_stopped():
    with pytest.raises(GcodeError, match="endless loop"):
        Interpreter("o1 while [1]\no1 endwhile\nM2\n", max_blocks=10_000).run()


def test_o_word_structure_errors():
    with pytest.raises(GcodeError, match="never closed") as e:
        _ends("G0 X1\no1 if [1]\nG0 X2\nM2\n")
    assert e.value.line == 2
    with pytest.raises(GcodeError, match="o1 while is never closed"):
        _ends("o1 while [0]\no2 endwhile\nM2\n")  # (the o2 endwhile: refused when reached)
    with pytest.raises(GcodeError, match="without a matching"):
        _ends("o1 while [0]\no2 if [1]\no1 endwhile\no2 endif\nM2\n")
    with pytest.raises(GcodeError, match="not defined in this file"):
        _ends("o<elsewhere> call\nM2\n")


_SUB = "o100 sub\nG0 X{}\no100 endsub\n"


def test_a_subroutine_is_defined_where_linuxcnc_passes_it_and_never_twice():
    # LinuxCNC 2.9 (measured; tests/toolpath/test_linuxcnc_oracle.py runs the same programs):
    # a second definition of a label is refused when reached ('redefining sub'), where woodcam
    # ran the calls with the second one
    with pytest.raises(GcodeError, match=r"line 4: 'o100 sub': subroutine o100 is defined a "
                                         r"second time \(first on line 1\)"):
        _ends(_SUB.format(1) + _SUB.format(2) + "o100 call\nM2\n")
    # a call before any definition searches forward and runs the first one after it (X1, not X2)
    assert _ends("o100 call\nM2\n" + _SUB.format(1) + _SUB.format(2)) == [(1, 0, 0)]
    # the definition a call found that way, passed over afterwards, is refused ('found in
    # illegal location'), as is one a loop passes over twice: after the moves before
    for text, line, before in (
            ("o100 call\nG0 X5\n" + _SUB.format(1) + "M2\n", 3, [(1, 0, 0), (5, 0, 0)]),
            ("o1 while [#1 lt 2]\n#1=[#1+1]\n" + _SUB.format(1) + "o100 call\no1 endwhile\nM2\n",
             3, [(1, 0, 0)])):
        interp = Interpreter(text, start_mm=(0, 0, 0))
        with pytest.raises(GcodeError, match=rf"line {line}: 'o100 sub': the o100 sub "
                                             "definition is reached a second time"):
            interp.run()
        assert [m[2] for m in interp.moves] == before
    # a definition in a branch not taken is never defined: the call finds none after it
    with pytest.raises(GcodeError, match=r"line 6: 'o100 call': the o100 sub definition "
                                         r"\(line\(s\) 2\) was never passed over"):
        _ends("o1 if [0]\n" + _SUB.format(1) + "o1 endif\no100 call\nM2\n")
    assert _ends("o1 if [1]\n" + _SUB.format(1) + "o1 endif\no100 call\nM2\n") == [(1, 0, 0)]


def _x_before(text, line, rule):
    """The moves ``text`` made before it was refused on ``line`` with ``rule`` (a regex)."""
    interp = Interpreter(text, start_mm=(0, 0, 0))
    with pytest.raises(GcodeError, match=rf"line {line}: .*{rule}"):
        interp.run()
    return [m[2][0] for m in interp.moves]


_IF = "o{} if [1]\nG0 X{}\no{} endif\n"
_SUB2 = "o2 sub\n" + _IF.format(1, 1, 1) + "o2 endsub\n"


def test_a_label_reused_in_one_scope_is_refused_when_reached_as_linuxcnc_does():
    # LinuxCNC 2.9 (measured; the same programs in test_linuxcnc_oracle.py): the first
    # if/while/do/repeat line reached with a label keeps it, per subroutine or main program and
    # across calls; another line with it is refused when reached ('duplicate O-word label').
    # woodcam ran them all
    dup = "labels the o1 {} on line {} already, in {}"
    assert _x_before(_IF.format(1, 1, 1) + _IF.format(1, 2, 1) + "M2\n", 4,
                    dup.format("if", 1, "the main program")) == [1]
    assert _x_before("o1 while [#1 lt 2]\n#1=[#1+1]\nG0 X#1\no1 endwhile\n"
                    "o1 repeat [2]\nG0 X5\no1 endrepeat\nM2\n", 5,
                    dup.format("while", 1, "the main program")) == [1, 2]
    # in a subroutine: across its calls (a branch of the second call), not across subroutines
    sub = ("o2 sub\no3 if [#1 eq 1]\n" + _IF.format(1, 1, 1) + "o3 else\n" + _IF.format(1, 2, 1)
           + "o3 endif\no2 endsub\n")
    assert _x_before(sub + "o2 call [1]\no2 call [2]\nM2\n", 7,
                    dup.format("if", 3, "subroutine o2")) == [1]
    assert _ends(_SUB2 + "o3 sub\n" + _IF.format(1, 2, 1) + "o3 endsub\n" + _IF.format(1, 3, 1)
                 + "o2 call\no3 call\no2 call\nM2\n") == [(3, 0, 0), (1, 0, 0), (2, 0, 0),
                                                          (1, 0, 0)]
    # a do keeps the first: a second do loop with the label runs while its test is false ...
    assert _ends("o1 do\nG0 X1\no1 while [0]\no1 do\nG0 X2\no1 while [0]\nM2\n") == [
        (1, 0, 0), (2, 0, 0)]
    # ... and is refused where LinuxCNC loops back to the first do (it hangs here), as is a
    # while loop reusing a do's label (LinuxCNC reads its while as the do's end)
    assert _x_before("o1 do\nG0 X1\no1 while [0]\n#2=0\no1 do\n#2=[#2+1]\nG0 X[#2+10]\n"
                    "o1 while [#2 lt 2]\nM2\n", 8, "goes back to the o1 do it reached first, "
                    "on line 1") == [1, 11]
    assert _x_before("o1 do\nG0 X1\no1 while [0]\no1 while [1]\no1 endwhile\nM2\n", 4,
                    "reads this o1 while as the end of that do loop") == [1]
    # a do loop's while after an if with its label is refused after the loop's first pass
    assert _x_before(_IF.format(1, 1, 1) + "o1 do\nG0 X2\no1 while [0]\nM2\n", 6,
                    dup.format("if", 1, "the main program")) == [1, 2]
    # skipping to the end of an if or loop by its label, LinuxCNC reads the lines with that
    # label on the way: a nested if/while/repeat with it is refused there though not run
    assert _x_before("o10 if [0]\no10 if [1]\nG0 X1\no10 endif\nG0 X2\no10 endif\nM2\n", 2,
                    "lies inside the o10 if of line 1") == []
    assert _x_before("o10 while [1]\nG0 X3\no10 break\no10 if [1]\no10 endif\no10 endwhile\n"
                    "M2\n", 4, "lies inside the o10 while of line 1") == [3]
    assert _x_before(_IF.format(10, 1, 10).replace("endif", "else") + _IF.format(10, 5, 10)
                    + "o10 endif\nM2\n", 4, "lies inside the o10 if of line 1") == [1]
    # a label in a branch not taken, or skipped for another label, was never reached
    assert _ends("o1 if [0]\n" + _IF.format(2, 1, 2) + "o1 endif\n" + _IF.format(2, 2, 2)
                 + "M2\n") == [(2, 0, 0)]
    assert _ends("o20 while [1]\no10 if [1]\no20 break\n" + _IF.format(10, 1, 10)
                 + "o10 endif\no20 endwhile\nG0 X4\nM2\n") == [(4, 0, 0)]


def test_an_error_in_an_elseif_condition_names_its_line():
    # it named the if's line (LinuxCNC: the elseif's; checked against its interpreter)
    for text, line in (("o1 if [0]\no1 elseif [#<undefined>]\no1 endif\nM2\n", 2),
                       ("o1 if [0]\no1 elseif [0]\nG0 X1\no1 elseif [1/0]\no1 endif\nM2\n", 4)):
        with pytest.raises(GcodeError, match=rf"line {line}: "):
            _ends(text)


def test_work_offsets_g10_g5x_g92():
    # (expected values checked against LinuxCNC 2.9's own interpreter)
    ends = _ends("G0 X1 Y1 Z1\nG10 L20 P1 X0\nG0 X2\nG10 L2 P2 X10 Y10\nG55 G0 X1 Y1\n"
                 "G92 X0 Y0\nG0 X1\nG92.1\nG0 X1\nG92 X5\nG92.2\nG0 X1\nG92.3\nG0 X1\n"
                 "G54\nG0 X0 Y0\nG59.3 G0 X0\nM2\n")
    # (G92.2 G0 X1 repeats the previous point: no move)
    assert [e[:2] for e in ends] == [(1, 1), (3, 1), (11, 11), (12, 11), (11, 11), (7, 11),
                                     (-3, 0), (-4, 0)]
    assert _ends("G10 L2 P9 X1 Y2 Z3\nG59.3 G0 X0 Y0 Z0\nM2\n")[0] == (1, 2, 3)
    with pytest.raises(GcodeError, match="G10 L2 and G10 L20"):
        _ends("G10 L1 P1 Z5\nM2\n")


def test_units_incremental_g53_g28():
    assert _ends("G20 G0 X1\nG91 G0 X1\nG90 G21 G0 Y3\nM2\n") == [
        (25.4, 0, 0), (50.8, 0, 0), (50.8, 3, 0)]
    moves, _ = Interpreter("G10 L2 P1 X5\nG54 G0 X1\nG53 G0 X1\nG28\nM2\n",
                           start_mm=(0, 0, 30)).run()
    assert [m[2] for m in moves] == [(6, 0, 30), (1, 0, 30), (0, 0, 30)]


def test_m61_loads_a_tool_and_keeps_the_selected_one_for_the_next_m6():
    """M61 Qn says tool n is loaded and leaves the T word's selection as it was (LinuxCNC sets
    only its loaded tool; checked against its interpreter in test_linuxcnc_oracle): a later M6
    loads the selected tool. Woodcam made M61's tool the selected one too, so "T5 / M61 Q3 /
    M6" cut with T3 where the machine loads T5, and #<_selected_tool> read 3."""
    def run(text):
        moves, warns = Interpreter(text + "\nM2\n", start_mm=(0, 0, 10)).run()
        return ([(m[2][:2], m[8]) for m in moves],
                [w for _, w in warns if "selected without M6" in w])

    moves, warns = run("T5\nM61 Q3\nG0 X#<_selected_tool> Y#<_current_tool>\nM6\n"
                       "G1 X1 Y1 Z0 F100")
    assert moves == [((5, 3), 3), ((1, 1), 5)] and warns == []
    # the selected T5 not loaded: the cut goes on with M61's T3, and says so
    assert run("T5\nM61 Q3\nG1 X1 Y1 Z0 F100") == ([((1, 1), 3)], [
        "T5 was selected without M6: the cut goes on with the loaded tool T3, as the "
        "controller does"])
    # no T word pending (none, or changed by M6 before M61): no such warning
    assert run("M61 Q3\nG1 X1 Y1 Z0 F100") == ([((1, 1), 3)], [])
    assert run("T5 M6\nM61 Q3\nG1 X1 Y1 Z0 F100\nG0 X#<_selected_tool>") == (
        [((1, 1), 3), ((5, 1), 3)], [])


def test_position_and_tool_parameters_read_as_linuxcnc():
    """#5420-#5422 are the current position in the program's units and frame (checked against
    LinuxCNC's interpreter); they read 0. #5400 missed M61. The read-only ones could be
    assigned, and tool-table, probe and input values the machine would supply read 0."""
    assert _ends("G0 X5 Y6 Z7\nG0 X[#5420+1] Y[#5421+1] Z[#5422+1]\nM2\n")[1] == (6, 7, 8)
    # G20, G55 with its X offset at 1 inch: program X0 Y2 Z3 (inch)
    ends = _ends("G20 G0 X1 Y2 Z3\nG55\nG10 L2 P2 X1\nG0 X#5420 Y[#5421+1] Z#5422 \nM2\n")
    assert ends[-1] == pytest.approx((25.4, 76.2, 76.2))
    assert _ends("G0 X1 Y2 Z3\nG91\nG0 X#5420 Y#5423\nM2\n")[-1] == (2, 2, 3)
    assert _ends("G0 X1\nG92 X0\nG0 Y[#5420+1]\nM2\n")[-1] == (1, 1, 0)
    assert _ends("T3 M6\nG0 X#5400\nM61 Q5\nG0 Y#5400\nM2\n")[-1] == (3, 5, 0)
    assert _ends("G0 X#5599 Y#5600 Z1\n#5061=2\nG0 X#5061\nM2\n") == [(1, 0, 1), (2, 0, 1)]
    for n in (5400, 5401, 5410, 5420, 5428):
        with pytest.raises(GcodeError, match=f"#{n} is a read-only system parameter"):
            _ends(f"#{n} = 3\nM2\n")
    with pytest.raises(GcodeError, match="#5410 is the loaded tool's .* tool table"):
        _ends("G0 X#5410\nM2\n")
    with pytest.raises(GcodeError, match="#5063 holds a G38 probe result"):
        _ends("G0 Z#5063\nM2\n")
    with pytest.raises(GcodeError, match="#5399 holds an M66 input"):
        Interpreter("#5399=1\nG0 X#5399\nM66 P0\nG0 X#5399\nM2\n").run()
    # values given through params: a probe result is taken; the machine's state (which the
    # interpreter keeps itself) was silently ignored, #5401-#5413 refused though supplied
    assert _ends("G0 Z#5063\nM2\n", params={5063: 4}) == [(0, 0, 4)]
    for n in (5400, 5403, 5420, 5428, 5600):
        with pytest.raises(WoodcamError, match=rf"params: #{n} is the machine's state.*got "
                           rf"params \[{n}\]; leave them out"):
            Interpreter("G0 X#5403\nM2\n", params={n: 2.0})


def test_parameter_lengths_are_mm_whatever_the_units():
    """A metric machine's parameters: G28 in a G20 program went to 25.4x the stored home (Z254
    for a home at Z10), G10 L2 in G20 stored inches that G55 then read as mm."""
    start = (0, 7, 10)
    home = Interpreter("G20 G90\nG0 X1 Y1 Z1\nG28\nM2\n", start_mm=start).run()[0]
    assert home[-1][2] == pytest.approx(start)
    home = Interpreter("G20 G91 G28 Z0\nM2\n", start_mm=start).run()[0]
    assert home == []  # already at the home (was a rapid up to Z254)
    assert _ends("G20\nG10 L2 P2 X1\nG55 G0 X0 Y0 Z0\nM2\n")[-1] == pytest.approx((25.4, 0, 0))
    # #5221 holds 76.2 (mm) after G10 L2 P1 X3 in G20: G21 X#5221 is 76.2 past the offset
    assert _ends("G20\nG10 L2 P1 X3\nG21 G0 X#5221 Y0 Z5\nM2\n")[-1][0] == pytest.approx(152.4)
    assert _ends("G20\nG0 X1 Y0 Z0\nG92 X0\nG21 G0 X#5211\nM2\n")[-1][0] == pytest.approx(50.8)


def test_feed_is_read_in_the_units_of_its_f_word():
    # LinuxCNC converts F when it is read (measured with its interpreter): a later G20/G21 keeps
    # the physical feed, and on a "G20 ... F10" line F comes before the units switch (10 mm/min);
    # woodcam scaled the F number by the units of each move (300 mm/min became 300 inch/min)
    prog = read_gcode("G21 G90\nG0 X0 Y0 Z5\nG1 X10 F300\nG20\nG1 X1\nG1 X2 F40\nG21\n"
                      "G1 X80\nG20 G1 X4 F10\nM2\n")
    assert prog.feed_mm_min.tolist() == pytest.approx([0, 300, 300, 1016, 1016, 10])
    assert prog.machining_time_s()[0][0] == pytest.approx(
        60 * (10 / 300 + 15.4 / 300 + 25.4 / 1016 + 29.2 / 1016 + 21.6 / 10))
    # grbl converts F with the units of its own line (gc_execute_line): 10 inch/min
    grbl = read_gcode("G21 G90\nG0 X0 Y0 Z5\nG1 X10 F300\nG20\nG1 X1\nG20 G1 X4 F10\n",
                      dialect="grbl")
    assert grbl.feed_mm_min.tolist() == pytest.approx([0, 300, 300, 254])


def test_arcs_r_form_turns_and_planes():
    moves, _ = Interpreter("G0 X0 Y0 Z0\nG2 X10 R5 F100\nG3 X0 R-5\n"
                           "G17 G91 G2 X10 Y0 I5 J0 P2\nG18 G90 G2 X20 Z0 I5 K0\n"
                           "G19 G3 Y10 Z0 J5 K0\nG2 J3\nM2\n",
                           start_mm=(0, 0, 0)).run()
    arcs = [m for m in moves if m[0] == 2]
    assert [(a[3], a[4], a[5]) for a in arcs[:2]] == [((5.0, 0.0), -1, 17), ((5.0, 0.0), 1, 17)]
    assert arcs[2][2] == (10, 0, 0) and arcs[2][3] == (5, 0) and arcs[2][4] == -2
    assert arcs[3][3] == (0, 15) and arcs[3][5] == 18         # (Z, X) centre in G18
    assert arcs[4][3] == (5, 0) and arcs[4][5] == 19          # (Y, Z) centre in G19
    assert arcs[5][2] == arcs[4][2] and arcs[5][4] == -1      # G2 I3: a full circle here
    # LinuxCNC's radius tolerance: 0.028 mm on a 10 mm radius is read, 0.029 mm refused
    _ends("G0 X0 Y0\nG2 X20.028 Y0 I10 J0 F100\nM2\n")
    with pytest.raises(GcodeError, match="radius to end of arc"):
        _ends("G0 X0 Y0\nG2 X20.029 Y0 I10 J0 F100\nM2\n")
    # LinuxCNC's zero-radius limit, 0.00005 inch: 0.00126 mm refused, 0.00128 mm read (the
    # 0.001 mm arc of a CAM post's arc fitting was read; LinuxCNC stops the program there)
    _ends("G0 X0 Y0\nG2 X0.00256 Y0 I0.00128 J0 F100\nM2\n")
    _ends("G20 G0 X0 Y0\nG2 X0.000102 Y0 I0.000051 J0 F10\nM2\n")
    for arc in ("G21 G2 X0.00252 Y0 I0.00126 J0", "G21 G2 X0.002 Y0 I0.001 J0",
                "G20 G2 X0.000098 Y0 I0.000049 J0"):
        with pytest.raises(GcodeError, match="line 2: 'G2': zero-radius arc"):
            _ends(f"G0 X0 Y0\n{arc} F100\nM2\n")


def test_r_arc_short_of_the_half_chord_is_refused_as_linuxcnc_does():
    # LinuxCNC 2.9 reads an R arc whose |R| is short of the half chord by up to 0.00005 inch
    # (centre at the chord's midpoint) and refuses more, in G20 and G21 alike; woodcam used
    # the centre-format tolerance (0.028 mm, 0.072 mm in G20) and cut "G2 X10 R4.99"
    moves, _ = Interpreter("G0 X0 Y0\nG2 X10 Y0 R4.99874 F100\nM2\n").run()
    assert moves[-1][3] == pytest.approx((5.0, 0.0), abs=1e-12)
    _ends("G20 G0 X0 Y0\nG2 X1 Y0 R0.499951 F10\nM2\n")
    for arc in ("G21 G2 X10 Y0 R4.99872", "G21 G2 X10 Y0 R4.99", "G21 G3 X10 Y0 R-4.995",
                "G20 G2 X1 Y0 R0.499949", "G21 G18 G2 X10 Z0 R4.993"):
        with pytest.raises(GcodeError,
                           match=r"line 2: 'R[-.0-9]+': arc radius .* too small to reach"):
            _ends(f"G0 X0 Y0 Z0\n{arc} F100\nM2\n")


def test_arc_lines_without_axis_words_as_linuxcnc_runs_them():
    # LinuxCNC 2.9 runs the modal arc on a line of I/J/K alone (a full circle; with P, turns)
    # and refuses a G2/G3 written with neither an end nor a centre; woodcam refused the
    # first ("I word with no G2/G3") and read the second as a mode change
    moves, _ = Interpreter("G0 X0 Y0 Z0\nG2 X10 I5 F100\nI5\nG91 J5 P2\nM2\n").run()
    assert [(m[1], m[2], m[3], m[4]) for m in moves[-2:]] == [
        (3, (10, 0, 0), (15, 0), -1), (4, (10, 0, 0), (10, 5), -2)]
    for line in ("G3", "G2 F200", "G3 M3", "G3 P2"):
        with pytest.raises(GcodeError, match="line 3: 'G[23]': G[23] with no end point"):
            _ends(f"G0 X0 Y0 Z0\nG2 X10 I5 F100\n{line}\nM2\n")
    with pytest.raises(GcodeError, match="line 4: 'I5': I word with no G2/G3"):
        _ends("G0 X0 Y0 Z0\nG2 X10 I5 F100\nG1 X0\nI5\nM2\n")


def test_a_dwell_beside_an_arc_is_refused_as_linuxcnc_does():
    # "G2 ... G4 P1": LinuxCNC refuses the line (both codes read P); woodcam cut the arc with
    # P turns and dwelt P seconds. A G4 beside a modal arc (no G2 written) runs both there.
    for line in ("G2 X10 Y0 I5 J0 G4 P1", "G3 X10 Y0 I5 J0 P1 G4", "G4 P0.5 G2 X10 I5"):
        with pytest.raises(GcodeError, match="line 2: 'G4 G[23]': G4 and G[23] on one line"):
            _ends(f"G0 X0 Y0 Z0 F100\n{line}\nM2\n")
    moves, _ = Interpreter("G0 X0 Y0 Z0\nG2 X10 I5 F100\nG4 P1 I5\nM2\n").run()
    assert moves[-1][3] == (15, 0) and moves[-1][4] == -1


def test_an_absolute_centre_arc_needs_both_centre_words():
    # G90.1: I/J/K are the centre's coordinates. LinuxCNC 2.9 refuses an arc missing one ("J
    # word missing in absolute center arc"); woodcam took the start's coordinate for it and cut
    # "G90.1 G2 X10 I5" round (5, 0) from (0, 0) and "G2 X10 Y0 J0" as a zero-radius arc
    for arc, word in (("G17 G2 X10 I5", "J"), ("G17 G2 X10 Y0 J0", "I"),
                      ("G18 G2 X10 I5", "K"), ("G19 G3 Y10 K0", "J")):
        with pytest.raises(GcodeError, match=f"line 3: 'G[23]': {word} word missing in an "
                                             "absolute-centre arc"):
            _ends(f"G0 X0 Y0 Z0\nG90.1 F100\n{arc}\nM2\n")
    moves, _ = Interpreter("G0 X0 Y0 Z0\nG90.1 G18 G2 X10 I5 K0 F100\nM2\n").run()
    assert moves[-1][3] == (0, 5) and moves[-1][5] == 18


@pytest.mark.parametrize("dialect", ["grbl", "linuxcnc"])
def test_grbl_system_commands_are_refused_naming_what_they_do(dialect):
    # "$H" opens many hand-written grbl programs: not G-code (LinuxCNC: "Bad character '$'
    # used"; grbl's sender hands it to the controller, which homes). woodcam said "bad
    # character '$'", naming neither the command nor what to do
    for line, what, fix in (("$H", "homing", "home the machine before the job"),
                            ("$J=G91 X10 F500", "jog", "write the move as a G0/G1 line"),
                            ("$X", "alarm unlock", "it does not move the machine"),
                            ("$110=2000", "a setting change", "set the controller beforehand"),
                            ("$$", "a settings, state or build report", "remove the line")):
        with pytest.raises(GcodeError, match=rf"line 2: '{re.escape(line[:3].upper())}.*': "
                                             rf"grbl system command \({what}.*{fix}"):
            _ends(f"G21 G90\n{line}\nG0 X1 Y1 Z1\nG1 X2 F100\nM2\n", dialect=dialect)


def test_g52_local_offset_as_linuxcnc():
    # LinuxCNC 2.9 runs G52 (woodcam refused it as an unsupported G code): the G92 offset is
    # set to the words themselves, axis by axis, in G90 and G91 alike and in program units;
    # G92 replaces it, G92.1 clears it, G92.3 restores it (numbers from LinuxCNC's interpreter)
    ends = _ends("G0 X1 Y2 Z5\nG52 X10\nG0 X0 Y0\nG52 Y5\nG0 X1 Y1\nG52 X0 Y0\nG0 X2 Y2\nM2\n")
    assert ends == [(1, 2, 5), (10, 0, 5), (11, 6, 5), (2, 2, 5)]
    ends = _ends("G0 X1 Y2 Z5\nG91 G52 X10\nG0 X1\nG90 G0 X0\nG20 G52 X1\nG0 X0\nM2\n")
    assert ends == [(1, 2, 5), (2, 2, 5), (10, 2, 5), (pytest.approx(25.4), 2, 5)]
    ends = _ends("G0 X1 Y2 Z5\nG52 X10 Y3\nG92 X0\nG0 X1 Y1\n#1=#5211 #2=#5212 #3=#5210\n"
                 "G0 X#1 Y#2 Z#3\nG92.2\nG0 X0 Y0\nG92.3\nG0 X0\nM2\n")
    assert ends == [(1, 2, 5), (2, 4, 5), (2, 6, 1), (0, 0, 1), (1, 0, 1)]
    for prog, match in (("G52\n", "line 1: 'G52': G52 needs axis words"),
                        ("G52 X1 G92 Y0\n", "line 1: 'G52 G92': two non-modal G codes")):
        with pytest.raises(GcodeError, match=match):
            _ends(prog + "G0 X1\nM2\n")
    with pytest.raises(GcodeError, match="line 1: 'G52': grbl has no G52"):
        _ends("G52 X1\nG0 X1\n", dialect="grbl")


@pytest.mark.parametrize("dialect", ["linuxcnc", "fanuc", "grbl"])
def test_old_units_codes_g70_g71_are_refused_naming_g20_g21(dialect):
    # Vectric's Mach3 mm post writes "G00G21G17G90G40G49G80" then "G71G91.1": LinuxCNC refuses
    # G71 (a lathe cycle there); woodcam said "unsupported G code ... post-process the program
    # for a 3-axis mill", which a mill program already is
    for code, units, fix in (("G71", "mm", "G21"), ("G70", "inch", "G20")):
        with pytest.raises(GcodeError, match=rf"line 2: '{code}': {code} is an old {units} "
                                             rf"units code .* replace it by {fix}"):
            _ends(f"G00G21G17G90G40G49G80\n{code}G91.1\nG0 X1 Y1 Z1\nM2\n", dialect=dialect)


@pytest.mark.parametrize("dialect, controller, read", [
    ("linuxcnc", "LinuxCNC", "LinuxCNC reads it as a lathe cycle and refuses it"),
    ("fanuc", "a Fanuc control", "a Fanuc control reads the units as G20/G21"),
    ("grbl", "grbl", "grbl refuses it")])
def test_a_dialect_s_messages_name_its_own_controller(dialect, controller, read):
    """--dialect fanuc's G71 said "LinuxCNC reads it as a lathe cycle ...; ... or post for
    LinuxCNC", and a code woodcam does not simulate "(LinuxCNC runs it)", to a Fanuc user. Each
    dialect's messages name its own controller; an M98 line's rules are woodcam's (as LinuxCNC)."""
    with pytest.raises(GcodeError) as e:
        _ends("G21 G90\nG71\nG0 X1 Y1 Z1\nM2\n", dialect=dialect)
    assert f"units code (Mach3, old Fanuc posts); {read}" in str(e.value), str(e.value)
    assert str(e.value).endswith(f"or post for {controller}"), str(e.value)
    with pytest.raises(GcodeError) as e:
        _ends("G0 X0 Y0 Z10 F100\nG38.2 X1 Z-3\nM2\n", dialect=dialect)
    assert ("(LinuxCNC runs it)" in str(e.value)) == (dialect == "linuxcnc"), str(e.value)
    if dialect != "grbl":
        for line, said in (("X1 M98 P100", "M98 after other words: woodcam reads a subprogram "
                            "call or return only as the first word of its line (after its N "
                            "word), as LinuxCNC does"),
                           ("M98 P100 X1", "only: woodcam reads no other word on it (LinuxCNC "
                            "skips them without a word)")):
            with pytest.raises(GcodeError, match=re.escape(said)):
                _ends(f"G0 X0 Y0 Z10\n{line}\nM30\nO100\nG1 X2 F100\nM99\n", dialect=dialect)


def test_lines_are_numbered_and_blanks_read_as_linuxcnc_does(tmp_path):
    # LinuxCNC and editors break lines at "\n" only and skip only spaces, tabs and the CR of a
    # line end. woodcam read files with universal newlines and split with str.splitlines, so
    # "\r\r\n" line ends (a twice-converted file) doubled every line number in its errors, a
    # form feed shifted the later ones, "G1 X5\r Y5" became two moves, and a no-break space
    # (copied from a web page) or vertical tab, which LinuxCNC refuses, was read as a blank
    path = tmp_path / "twice_converted.ngc"
    path.write_bytes(b"G21 G90\r\r\nG0 X0 Y0 Z5\r\r\nG1 Z-1 F100\r\r\nG1 X5 Y\r\r\nM2\r\r\n")
    with pytest.raises(GcodeError, match="line 4: 'g1x5y': a value is missing"):
        read_gcode(path)
    path.write_bytes(b"G21 G90\nG0 X0 Y0 Z5\nG1 Z-1 F100\nG1 X5\r Y5\nM2\n")
    assert read_gcode(path).end_mm.tolist()[-1] == [5, 5, -1]
    for bad, shown in (("\x0c", r"\\x0c"), ("\xa0", r"\\xa0"), ("\x0b", r"\\x0b")):
        with pytest.raises(GcodeError, match=f"line 3: '{shown}': bad character"):
            _ends(f"G21 G90\n(a{bad}comment)\nG1{bad}X5 F100\nG1 X6 Y\nM2\n")
    # a form feed inside a comment is the comment's: the next error is named on its own line
    with pytest.raises(GcodeError, match="line 4: 'g1x6y'"):
        _ends("G21 G90\n(a\x0ccomment)\nG1 X5 F100\nG1 X6 Y\nM2\n")
    # a file whose lines end in CR alone (classic Mac OS) is read line by line, with a warning
    moves, warnings = Interpreter("G0 X1 Y1 Z1\rG1 X2 F100\rM2\r").run()
    assert moves[-1][1:3] == (2, (2, 1, 1)) and "CR alone" in warnings[0][1]


def test_a_percent_line_with_a_form_feed_is_no_delimiter_as_linuxcnc_reads_it():
    # Review of 6f01841: only space, tab and CR are blanks (a form feed, vertical tab or
    # no-break space is LinuxCNC's "Bad character"), yet a '%' line was told by str.strip(),
    # which also strips those: "\x0c%" opened or closed a %-delimited program, the moves after
    # a closing one silently dropped, where LinuxCNC refuses the line
    for bad, shown in (("\x0c", r"\\x0c"), ("\x0b", r"\\x0b"), ("\xa0", r"\\xa0")):
        with pytest.raises(GcodeError, match=f"line 4: '{shown}': bad character"):
            _ends(f"%\nG21 G90\nG0 X0 Y0 Z5\n{bad}%\nG1 Z-1 F100\n%\n")
        with pytest.raises(GcodeError, match=f"line 1: '{shown}': bad character"):
            _ends(f"{bad}%\nG21 G90\nG0 X0 Y0 Z5\n%\n")
    # blanks LinuxCNC skips still leave a delimiter: space, tab, the CR of a CRLF line end
    assert _ends("% \t\r\nG21 G90\r\nG0 X1 Y2 Z5\r\n\t%\r\nG0 X9\r\n")[-1] == (1, 2, 5)


def test_a_byte_order_mark_is_refused_naming_it(tmp_path):
    # Notepad's "UTF-8 with BOM" puts EF BB BF before the first line; LinuxCNC refuses it
    # ("Bad character '\\357' used"), and woodcam did too, as "bad character '\\ufeff'"
    for first in ("G21 G90", "(post: a comment first)"):
        path = tmp_path / "bom.ngc"
        path.write_bytes(b"\xef\xbb\xbf" + f"{first}\nG0 X0 Y0 Z5\nG1 Z-1 F100\nM2\n".encode())
        with pytest.raises(GcodeError, match="line 1: 'BOM': a byte-order mark .* save the "
                                             "file as UTF-8 without BOM"):
            read_gcode(path)
    # two files joined (roughing, then finishing), the second saved with a BOM: its line
    with pytest.raises(GcodeError, match="line 3: 'BOM': a byte-order mark"):
        _ends("G21 G90\nG0 X0 Y0 Z5\n\ufeffG1 Z-1 F100\nM2\n")


def test_g10_needs_p_and_reads_a_zero_rotation_as_linuxcnc():
    # LinuxCNC 2.9 refuses G10 L2/L20 without P ("P value out of range (0-9)"), which woodcam
    # read as P0 (the active system); it runs "G10 L2 P1 R0 X2" (no rotation), which woodcam
    # refused as "'R0': arc words without an end point"; it refuses R in G10 L20
    for line, match in (("G10 L2 X2", "'G10 L2': G10 L2 without P"),
                        ("G10 L20 X2", "'G10 L20': G10 L20 without P"),
                        ("G10 L20 P1 R0 X2", "'R0': R \\(a rotation\\) is not allowed in G10 L20"),
                        ("G10 L2 P1 R30 X2", "'R30': G10 L2 R \\(rotated coordinate systems\\)")):
        with pytest.raises(GcodeError, match=f"line 2: {match}"):
            _ends(f"G0 X1 Y1 Z10\n{line}\nG0 X0\nM2\n")
    assert _ends("G0 X1 Y1 Z10\nG10 L2 P1 R0 X2\nG0 X0\nM2\n")[-1] == (2, 1, 10)


@pytest.mark.parametrize("code, what, fix", [
    ("G84", "a tapping cycle", "drill the hole with G81"),
    ("G88", "a boring cycle with a spindle stop", "use G85 or G89"),
    ("G38.2", "a probing move", "probe before the job"),
    ("G5.1", "a spline or NURBS", "post-process with lines and arcs"),
    ("G33.1", "threading or rigid tapping", "remove the threading; drill the hole with G81"),
    ("G43.2", "an added tool length offset", "remove it")])
def test_codes_linuxcnc_runs_but_woodcam_does_not_simulate_say_what_they_are(code, what, fix):
    # LinuxCNC 2.9 runs these; woodcam refuses them on purpose, and said "unsupported G code
    # ...; post-process the program for a 3-axis mill" (a tapping or probing line is 3-axis)
    with pytest.raises(GcodeError, match=rf"line 2: '{re.escape(code)}': {re.escape(code)} "
                                         rf"\({what}.*\) is not simulated by woodcam "
                                         rf"\(LinuxCNC runs it\); {fix}"):
        _ends(f"G0 X0 Y0 Z10 F100 S1000 M3\n{code} X1 Z-3 R2 P1 Q1 I1 J1 K1 H1\nM2\n")


def test_g53_g0_without_axis_words_moves_nothing_as_in_linuxcnc():
    # LinuxCNC 2.9 runs "G53 G0" and "G53 G1" without axis words (no move; the line's motion
    # mode is set), which woodcam refused as "G53 needs G0 or G1 and axis words"; it refuses a
    # G53 whose line has no G0/G1 to use ("Must use g0 or g1 with g53"), and woodcam alike
    # (test_g53_without_axis_words_agrees_with_linuxcnc compares both on these)
    start = "G21 G90 F100\nG0 X1 Y1 Z5\n"
    assert _ends(start + "G53 G0\nG0 X2\nM2\n") == [(1, 1, 5), (2, 1, 5)]
    assert _ends(start + "G53 G1\nX4\nM2\n") == [(1, 1, 5), (4, 1, 5)]  # X4 in G1, from the G53 line
    for line in ("G53", "G0 X3\nG53", "G2 X3 Y1 I1 J0\nG53", "G80\nG53", "G53 G2"):
        with pytest.raises(GcodeError, match=r"'G53': G53 needs G0 or G1 on its line, or axis words "
                                             r"in G0 or G1 mode \(LinuxCNC: 'Must use g0 or g1 with g53'\)"):
            _ends(start + line + "\nM2\n")
    with pytest.raises(GcodeError, match=r"'G53': G53 in incremental mode"):
        _ends(start + "G91\nG53 G0\nM2\n")


@pytest.mark.parametrize("code, what, fix", [
    ("M70", "saves the modal state for an M72", "write the modes M72 restores"),
    ("M71", "invalidates the modal state M70 or M73 saved", "remove it with the M70/M72 or M73"),
    ("M72", "restores the modal state M70 saved", "write the modes it restores"),
    ("M73", "saves the modal state, restored when the subroutine returns", "write the modes the caller needs")])
def test_modal_state_save_and_restore_say_what_they_are(code, what, fix):
    # LinuxCNC runs M70-M73; woodcam refuses them on purpose (the modes they restore would have
    # to be restored exactly), and said "unsupported M code ...; remove it or post-process for
    # a 3-axis mill", which names neither what the code does nor how to do without it
    with pytest.raises(GcodeError, match=rf"line 2: '{code}': {code} \({re.escape(what)}\) is not "
                                         rf"simulated by woodcam \(LinuxCNC runs it\); {re.escape(fix)}"):
        _ends(f"G0 X0 Y0 Z10 F100\n{code}\nG0 X1\nM2\n")


def test_m19_orients_the_spindle_which_then_stands_until_m3_or_m4():
    # LinuxCNC reads M19's R (angle), Q (timeout) and P (direction) and reports the spindle
    # stopped after it (the oracle's spindle state, LinuxCNC's standalone rs274 prints
    # ORIENT_SPINDLE and no restart); woodcam refused 'M19 R90' ("R word with no G or M code")
    # and cut on at the old speed after a bare M19
    text = ("G21 G90 F100\nS1000 M3\nG1 X5\nM19 R90 Q2 P1\nG1 X6\nM3 G1 X7\nM19\nG1 X8\n"
            "M4 G1 X9\nM19 R45 G1 X10\nM2\n")
    prog = read_gcode(text)
    assert prog.spindle_rpm.tolist() == [1000, 0, 1000, 0, 1000, 0]
    assert [w.split(":")[0] for w in prog.warnings if "M19" in w] == ["line 4", "line 7",
                                                                     "line 10"]
    assert prog.end_mm[:, 0].tolist() == [5, 6, 7, 8, 9, 10]


def test_break_and_continue_in_a_repeat_loop_are_refused_as_linuxcnc_does():
    # LinuxCNC 2.9 leaves or restarts only while and do loops: "o1 break" in an "o1 repeat" is
    # "no matching while/do label: 'o1 break' (found 'repeat' ...)" when reached; woodcam left
    # the loop (and "o1 continue" skipped to the next pass)
    for k in ("break", "continue"):
        text = (f"G0 X0 Y0 Z1\n#1=0\no1 repeat [3]\n#1=[#1+1]\no2 if [#1 eq 2]\no1 {k}\n"
                f"o2 endif\nG0 X#1\no1 endrepeat\nM2\n")
        with pytest.raises(GcodeError, match=rf"line 6: 'o1 {k}': {k} in an o1 repeat loop: "
                                             r"LinuxCNC leaves or restarts only while and do"):
            _ends(text)
        assert _ends(text.replace("[#1 eq 2]", "[#1 eq 9]"))[-1] == (3, 0, 1)  # not reached


def test_a_break_read_in_a_while_loop_ends_the_next_do_loop_as_in_linuxcnc():
    # LinuxCNC 2.9 (measured) sets a flag for every break it reads and clears it only at a do
    # loop's test: after a break out of a while loop, or one it runs while skipping to the end
    # of a while loop (its condition false, or after a continue), the next do loop ends after
    # one pass. A continue in a do loop followed by that loop's break ends the loop. woodcam
    # ran the do loops to their conditions
    do = "#<c> = 0\no7 do\n#<c> = [#<c> + 1]\nG1 X#<c> Y2\no7 while [#<c> LT 3]\nM2\n"
    start = "G0 X0 Y0 Z1 F100\n#<a> = 0\n"
    cases = {  # loop before the do loop -> X of its moves (LinuxCNC's)
        "o1 while [1]\no1 break\no1 endwhile\n": [1],
        "o2 while [#<a> LT 1]\n#<a> = [#<a> + 1]\no4 if [#<a> EQ 9]\no2 break\no4 endif\n"
        "o2 endwhile\n": [1],  # the break inside an if not taken, read on the way out
        "o2 while [0]\no2 break\no2 endwhile\n": [1],
        "o2 while [#<a> LT 2]\n#<a> = [#<a> + 1]\no3 if [#<a> EQ 1]\no2 continue\no3 endif\n"
        "o4 if [#<a> EQ 9]\no2 break\no4 endif\no2 endwhile\n": [1],
        "o2 while [#<a> LT 2]\n#<a> = [#<a> + 1]\no2 endwhile\n": [1, 2, 3],
        "o2 do\no2 break\no2 while [1]\n": [1, 2, 3],  # a do loop's test clears it
        "o1 sub\no2 while [1]\no2 break\no2 endwhile\no1 endsub\n": [1, 2, 3],  # not called
    }
    for loop, xs in cases.items():
        moves, warnings = Interpreter(start + loop + do, start_mm=(0, 0, 0)).run()
        assert [m[2][0] for m in moves if m[2][1] == 2] == xs, loop
        assert any("LinuxCNC 2.9 still carries the break" in w for _, w in warnings) == (
            len(xs) == 1), loop
    # a continue, then the do loop's own break: the loop ends there (LinuxCNC: X1, then Y1)
    ends = _ends("G0 X0 Y0 Z1 F100\n#<a> = 0\no2 do\n#<a> = [#<a> + 1]\no3 if [#<a> EQ 2]\n"
                 "o2 continue\no3 endif\nG1 X#<a>\no4 if [#<a> EQ 9]\no2 break\no4 endif\n"
                 "o2 while [#<a> LT 4]\nG1 Y1\nM2\n")
    assert ends[1:] == [(1, 0, 1), (1, 1, 1)]


def test_canned_cycles_retract_planes():
    # G99 returns to R, G98 to the initial level of the cycle series (LinuxCNC)
    ends = _ends("G0 X0 Y0 Z10\nG99 G81 X1 Y1 Z-2 R2 F100\nX2\nG98 G81 X3\nG80\nM2\n")
    assert ends == [(0, 0, 10), (1, 1, 10), (1, 1, 2), (1, 1, -2), (1, 1, 2), (2, 1, 2), (2, 1, -2),
                    (2, 1, 2), (3, 1, 10), (3, 1, 2), (3, 1, -2), (3, 1, 10)]
    # G83 pecks retract to R and come back 0.254 mm (0.010 inch) above the last depth
    ends = _ends("G0 X0 Y0 Z5\nG83 X1 Y1 Z-3 R1 Q1 F100\nG80\nM2\n")
    assert [round(e[2], 6) for e in ends] == [5, 5, 1, 0, 1, 0.254, -1, 1, -0.746, -2, 1,
                                              -1.746, -3, 1]


def test_g98_holes_travel_at_the_tools_z_and_retract_to_the_higher_of_initial_level_and_r():
    # LinuxCNC 2.9 (measured): each hole is reached at the tool's own Z (raised to R first when
    # below it) and G98 retracts to max(initial level, R). woodcam travelled at the initial
    # level: after a hole with R3 above the initial Z1 it dropped from Z3 to Z1 and crossed to
    # the next hole there (LinuxCNC stays at Z3), and after one with R10 it dropped to Z8
    ends = _ends("G0 X0 Y0 Z1\nG98 G81 X1 Y1 Z-3 R3 F100\nX4 R0\nG80\nM2\n")
    assert ends[-4:] == [(4, 1, 3), (4, 1, 0), (4, 1, -3), (4, 1, 1)]
    ends = _ends("G0 X0 Y0 Z8\nG98 G81 X1 Y1 Z-3 R3 F100\nX5 R10\nX6 R1\nG80\nM2\n")
    assert ends[5:] == [(1, 1, 10), (5, 1, 10), (5, 1, -3), (5, 1, 10),
                        (6, 1, 10), (6, 1, 1), (6, 1, -3), (6, 1, 8)]
    # at or below R the hole is reached at the retract plane (G98 after G99: the initial level)
    ends = _ends("G0 X0 Y0 Z10\nG99 G81 X1 Y1 Z-2 R2 F100\nG98 X3 R2.5\nG80\nM2\n")
    assert ends[-4:] == [(3, 1, 10), (3, 1, 2.5), (3, 1, -2), (3, 1, 10)]


def test_g86_with_the_spindle_stopped_is_refused_as_linuxcnc_does():
    # G86 stops the spindle at the bottom and restarts it: LinuxCNC refuses it with the spindle
    # stopped ("Spindle not turning in g86"); woodcam bored the hole
    with pytest.raises(GcodeError, match=r"line 2: 'G86': G86 .* spindle stopped: LinuxCNC "
                                         r"refuses it .*; start the spindle"):
        _ends("G0 X0 Y0 Z5\nG86 X1 Y1 Z-3 R2 P0.5 F100\nG80\nM2\n")
    with pytest.raises(GcodeError, match=r"line 4: 'G86'"):
        _ends("G0 X0 Y0 Z5\nM3 S1000\nG86 X1 Y1 Z-3 R2 P0.5 F100\nM5 X2\nG80\nM2\n")
    assert len(_ends("G0 X0 Y0 Z5\nM3 S1000\nG86 X1 Y1 Z-3 R2 P0.5 F100\nG80\nM2\n")) == 5


def test_a_cycle_code_after_another_mode_needs_its_own_words():
    # LinuxCNC 2.9 carries R, Z, Q (G73/G83) and P (G82/G86/G89) over only from lines of the
    # same cycle code; woodcam kept them from any earlier cycle (and P = 0 when never given),
    # drilling holes LinuxCNC refuses: "G81 ... / G82 X2 P1" (no R), "G83 ... / G73 X2 R2 Z-3"
    # (no Q), "G82 X1 Z-3 R2" (no P), a G81 after a G0 or G80 without R
    start = "G0 X0 Y0 Z10\n"
    for prog, word in (("G81 X1 Z-3 R2 F100\nG82 X2 Z-3 P1", "R"),
                       ("G81 X1 Z-3 R2 F100\nG82 X2 R2 P1", "Z"),
                       ("G83 X1 Z-3 R2 Q1 F100\nG73 X2 Z-3 R2", "Q"),
                       ("G82 X1 Z-3 R2 P1 F100\nG89 X2 Z-3 R2", "P"),
                       ("G82 X1 Z-3 R2 F100", "P"),
                       ("G81 X1 Z-3 R2 F100\nG0 X5\nG81 X2 Z-3", "R"),
                       ("G81 X1 Z-3 R2 F100\nG80\nG81 X2 Z-3", "R")):
        n = prog.count("\n") + 2
        with pytest.raises(GcodeError, match=rf"line {n}: 'G8\d|G73': .* without {word} "
                                             r"\(.*LinuxCNC keeps"):
            _ends(start + prog + "\nG80\nM2\n")
    # the same code goes on with the words it had (G82's P too), as in LinuxCNC
    ends = _ends(start + "G82 X1 Z-3 R2 P1 F100\nG82 X2\nM3\nX3\nG80\nM2\n")
    assert ends[-4:] == [(2, 0, 2), (3, 0, 2), (3, 0, -3), (3, 0, 2)]  # LinuxCNC's numbers


def test_cycle_repeats_travel_at_the_retract_plane():
    # G91 G99 with L: after the first hole the next ones are reached at R (LinuxCNC's
    # convert_cycle_xy sets old_cc = clear_cc after each repeat), not at the initial Z
    ends = _ends("G0 X0 Y0 Z5\nG91 G99 G81 X10 R-3 Z-5 L3 F100\nG90 G80\nM2\n")
    assert ends == [(0, 0, 5), (10, 0, 5), (10, 0, 2), (10, 0, -3), (10, 0, 2),
                    (20, 0, 2), (20, 0, -3), (20, 0, 2), (30, 0, 2), (30, 0, -3), (30, 0, 2)]


def test_incremental_cycle_series_count_r_from_the_initial_level():
    # "G91 G81 R-6 Z-5" from Z8, then "X5" lines: every hole has R at 8 - 6 = 2 and its bottom
    # at -3; R was counted from the Z the last hole retracted to (G99: R), so the second hole
    # went to -9, 6 mm too deep (LinuxCNC 2.9 drills all three to -3)
    ends = _ends("G0 X0 Y0 Z8\nG99 G91 G81 R-6 Z-5 F100\nX5\nX5\nG90 G80\nM2\n")
    assert min(e[2] for e in ends) == -3
    assert ends[-3:] == [(10, 0, 2), (10, 0, -3), (10, 0, 2)]
    # R and Z set in G90, the series continued in G91: R from the initial level too
    ends = _ends("G0 X0 Y0 Z8\nG81 R2 Z-3 F100\nG91 X5\nG90 G80\nM2\n")
    assert ends[-4:] == [(0, 0, 10), (5, 0, 10), (5, 0, 7), (5, 0, 10)]


def test_g43_1_axis_words_are_the_offset_not_a_move():
    # "G43.1 Z-5" in G1 mode fed 4 mm deeper; in LinuxCNC its axis words are the dynamic tool
    # length offset: nothing moves, and the tip is now 5 mm higher and 3 mm left (the
    # spindle stands: test_a_tool_length_offset_change_moves_the_tip_not_the_spindle)
    ends = _ends("G0 X0 Y0 Z5\nG1 Z-1 F100\nG43.1 X3 Z-5\nG1 X10\nG49\nM2\n")
    assert ends == [(0, 0, 5), (0, 0, -1), (10, 0, 4)]
    assert _ends("G0 X0 Y0 Z5\nG43.1 Z2 G1 X5 F100\nM2\n")[-1] == (5, 0, 2)


def test_cutter_compensation_is_refused_by_its_g_code_not_its_d_word():
    # "G41 D1" was refused as "unsupported word D (... no A/B/C/U/V/W axes)"
    with pytest.raises(GcodeError, match="line 2: 'G41': cutter radius compensation"):
        _ends("G0 X10 Y10 Z5\nG41 D1 G1 X20 Y20 F100\nG40\nM2\n")
    with pytest.raises(GcodeError, match="line 1: 'D1': D word with no G or M code"):
        _ends("G1 X1 D1 F100\nM2\n")


def test_dialects():
    safety = "G00 G17 G21 G40 G49 G80 G90\nG0 X1 Y1 Z5\nG1 Z-1 F100\n"
    for d in ("linuxcnc", "fanuc", "grbl"):
        assert len(read_gcode(safety + "M30\n", dialect=d)) == 2
    with pytest.raises(GcodeError, match="grbl has no parameters"):
        read_gcode("#1 = 3\nG0 X#1\n", dialect="grbl")
    with pytest.raises(GcodeError, match="grbl has no O-word"):
        read_gcode("o1 sub\no1 endsub\n", dialect="grbl")
    # an O1234 program number: LinuxCNC 2.9 runs through it (woodcam refused it there), as
    # Fanuc; grbl has none (nor the M98/M99 subprograms it labels: test_fanuc_style_subprograms)
    for d in ("fanuc", "linuxcnc"):
        assert len(read_gcode("O0042 (job)\n" + safety + "N9 O43\nM30\n", dialect=d)) == 2
    with pytest.raises(GcodeError, match="grbl has no O words"):
        read_gcode("O0042\n" + safety, dialect="grbl")
    # a missing program end is a warning in LinuxCNC's dialect only
    assert any("without M2" in w for w in read_gcode(safety).warnings)
    assert read_gcode(safety, dialect="grbl").warnings == []
    with pytest.raises(WoodcamError, match="dialect"):
        read_gcode(safety, dialect="haas")


_BODY = "G21 G90 F100\nG0 X0 Y0 Z5\nG1 X1\n"


def test_a_tool_length_offset_change_moves_the_tip_not_the_spindle():
    """LinuxCNC keeps the spindle where it is when G43.1/G43/G49 change the offset, so the tip
    it moves by the program's coordinates jumps by the change (measured against its
    interpreter in test_linuxcnc_oracle.py); woodcam ignored the offset: after G43.1 Z1 a G91
    Z-1 from Z10 ended at Z9, not Z8, and G53/G28 put the tip where the spindle goes."""
    ends = _ends("G0 Z10\nG43.1 Z1\nG91 G0 Z-1\nG90 G0 Z5\nG43.1 X0.5\nG91 G0 Y1\nG49\n"
                 "G0 Y1\nG90 G43.1 Z2\nG53 G0 Z20\nG28.1\nG49 G0 Z3\nG28\nM2\n")
    assert ends == [(0, 0, 10), (0, 0, 8), (0, 0, 5), (-0.5, 1, 5), (0, 2, 6), (0, 2, 18),
                    (0, 2, 3), (0, 2, 20)]  # absolute moves: the tip where the program says;
    # G53 Z20 and G28's home place the spindle, the tip the offset (2) lower
    # G43 takes the tool table's length as 0, so it ends an offset, and says so
    moves, warnings = Interpreter("G0 Z10\nG43.1 Z2\nG43\nG0 X1\nM2\n", start_mm=(0, 0, 0)).run()
    assert moves[-1][2] == (1, 0, 10)
    assert warnings == [(3, "G43 without H uses the loaded tool's length from the machine's tool "
                         "table, which woodcam does not know: tool table lengths are taken as 0 "
                         "(woodcam measures tools from the tip), so the offset becomes 0")]


_SUBS = """G21 G90 F100
#1 = 2 #<depth> = -1
G0 X0 Y0 Z5
M98 P1000 L2
G0 X#1 Y#2
M30
O1000 (a row of half circles, then 10 mm over)
G91 G1 Z#<depth>
M98 P2000 L#1
G91 G0 Z1 X10
G90
M99
O2000
#<depth> = 7 (a local of this call: O1000's #<depth> is undefined here)
G91 G3 X4 Y0 I2 J0
#1 = [#1 + 1] #2 = 5
G90
M99
"""


def test_fanuc_style_subprograms():
    """M98 P<n> [L<count>] calls the subprogram labelled O<n>, M99 returns: LinuxCNC 2.9 runs
    them (checked against its interpreter in test_linuxcnc_oracle.py), as Fanuc and Mach3 do;
    woodcam refused every M98/M99 line."""
    with pytest.raises(GcodeError, match="named parameter #<depth> not defined"):
        read_gcode(_SUBS)  # named parameters are the call's own, as in an o-word call
    text = _SUBS.replace("G91 G1 Z#<depth>", "G91 G1 Z-1")
    for dialect in ("linuxcnc", "fanuc"):
        assert read_gcode(text, dialect=dialect).warnings == []
        moves = Interpreter(text, dialect=dialect, start_mm=(0, 0, 10)).run()[0]
        # O1000 twice (L2); in it O2000 L#1: #1 is shared with the caller (no #1-#30 of its
        # own, unlike an o-word call) and L is read once per M98 line, so the first O1000
        # calls O2000 twice (#1 = 2 -> 4), the second four times (#1 -> 8)
        assert [m[1] for m in moves] == [3, 8, 15, 15, 10, 8, 15, 15, 15, 15, 10, 5]
        assert [moves[i][2] for i in (3, 4, 9, 10, 11)] == [
            (8, 0, 4), (18, 0, 5), (34, 0, 4), (44, 0, 5), (8, 5, 5)]
    # what LinuxCNC refuses, named: a missing label, recursion past its 9 calls, an M98 not
    # first on its line, an M99 return with words after it, a label before its first call
    _refused(_BODY + "M98 P7\nM30\n", 4, "M98 P7", "no O7 line in this file")
    _refused(_BODY + "M98 P7\nM30\nO7\nG91 G0 X1\nM98 P7\nM99\n", 8, "M98 P7",
             rf"more than {MAX_CALL_DEPTH} nested subroutine calls .*O7 > O7")
    _refused(_BODY + "G0 X1 M98 P7\nM30\nO7\nM99\n", 4, "M98", "first word of its line")
    _refused(_BODY + "M98 P7\nM30\nO7\nM99 P3\n", 7, "M99 P3", "nothing may follow an M99")
    _refused(_BODY + "O7\nG1 X2\nM98 P7\nM30\n", 6, "M98 P7", "O7 is on line 4, before the M98")
    _refused(_BODY + "M98 P7 X3\nM30\nO7\nM99\n", 4, "M98 X3", "P .* and L .* only")
    _refused(_BODY + "M98 P7\nM30\no7 sub\no7 endsub\n", 4, "M98 P7", "o-word subroutine")
    _refused(_BODY + "M98 P7\nM30\n", 4, "M98", "grbl has no subprograms", dialect="grbl")
    # a decimal point: LinuxCNC reads neither as a call or return (woodcam ran both)
    _refused(_BODY + "M98.0 P7\nM30\nO7\nM99\n", 4, "M98.0", "without a decimal point")
    _refused(_BODY + "M98 P7\nM30\nO7\nM99.0\n", 7, "M99.0", "without a decimal point")
    # Fanuc keeps its programs apart: the label may come first, and P51002 is O1002 5 times
    prog = read_gcode(_BODY + "M30\nO1002\nG91 G1 X1\nG90\nM99\nM98 P51002\n",
                      dialect="fanuc")
    assert len(prog) == 2  # (M30 came first: the call never runs)
    prog = read_gcode(_BODY + "M98 P51002\nM30\nO1002\nG91 G1 X1\nG90\nM99\n",
                      dialect="fanuc")
    assert prog.end_mm[-1].tolist() == [6.0, 0.0, 5.0]
    # M99 in the main program starts it again forever: one pass, and a warning naming the fix
    prog = read_gcode(_BODY + "G1 X2\nM99\n")
    assert len(prog) == 3
    assert prog.warnings == [
        "line 5: M99 in the main program: the control starts the program again from the top "
        "and repeats it forever (LinuxCNC, Fanuc and Mach3 alike); woodcam simulated one pass; "
        "replace this M99 with M30 (or M2) to stop after one pass"]


def _refused(text, line, word, rule, **kw):
    with pytest.raises(GcodeError, match=rule) as e:
        read_gcode(text, **kw)
    assert (e.value.line, e.value.word) == (line, word)


def test_a_percent_line_counts_only_as_linuxcnc_reads_it():
    """LinuxCNC refuses these ("Bad character '%' used", checked against its interpreter in
    test_linuxcnc_oracle.py); woodcam skipped the '%' and ran the moves after it."""
    rule = "'%' is read only as a line of its own"
    _refused(_BODY + "%\nG1 X50\nM2\n", 4, "%", rule)  # no opening '%'
    _refused("(header)\n%\n" + _BODY + "M2\n", 2, "%", rule)  # not the first line
    _refused("% (c)\n" + _BODY + "%\n", 1, "%", rule)  # a comment beside it
    _refused("%\n" + _BODY + "% (end)\nG1 X50\n", 5, "%", rule)
    # what LinuxCNC reads: blank lines before the opening '%', blanks around either; nothing
    # after the closing one; a '%' after the program end is never reached
    assert len(read_gcode("\n %\n" + _BODY + "\t%\nG1 X50\n")) == 2
    assert len(read_gcode(_BODY + "M2\n%\nG1 X50\n")) == 2


def test_a_percent_line_inside_a_grbl_program_is_skipped_with_a_warning():
    """grbl's firmware answers every '%' line with error:1; its senders drop the lines (UGS) or
    report the error and stream on (grbl's stream.py): the moves after any '%' run. woodcam
    skipped a stray '%' without a word, and ended the program at a second '%' (LinuxCNC's
    reading) where the senders run on."""
    prog = read_gcode(_BODY + "%\nG1 X50\n", dialect="grbl")
    assert len(prog) == 3
    assert prog.warnings == [
        "line 4: '%' on line(s) 4 inside the program: grbl's firmware answers it with error:1 "
        "(Expected command letter); senders drop the line or report the error and go on, so "
        "woodcam skipped it, but a sender that stops on errors stops the job there; keep '%' "
        "to the first and last line"]
    prog = read_gcode("%\n" + _BODY + "%\nG1 X50\n%\n", dialect="grbl")
    assert len(prog) == 3 and [w[:7] for w in prog.warnings] == ["line 5:"]
    # the delimiters a post writes first and last, comments around them: no warning
    prog = read_gcode("(post)\n%\n(job)\n" + _BODY + "M30\n%\n(end)\n", dialect="grbl")
    assert len(prog) == 2 and prog.warnings == []


def test_two_m_codes_of_one_modal_group_are_refused():
    """LinuxCNC: "Two m codes used from same modal group", "Too many m codes on line"; grbl
    refuses the pairs of its groups alike (error 21). woodcam ran ``M4 M5`` as M5."""
    _refused(_BODY + "M4 M5\nM2\n", 4, "M4 M5", "two spindle M codes on one line")
    _refused(_BODY + "M3 M3\nM2\n", 4, "M3 M3", "two spindle M codes")
    _refused(_BODY + "M7 M9\nM2\n", 4, "M7 M9", "two coolant M codes")
    _refused(_BODY + "M2 M30\n", 4, "M2 M30", "two stopping M codes")
    _refused(_BODY + "M3 M8 M48 M100 M6\nM2\n", 4, "M3 M8 M48 M100 M6",
             "more than 4 M codes on one line")
    _refused(_BODY + "M4 M5\n", 4, "M4 M5", "two spindle M codes", dialect="grbl")
    assert len(read_gcode(_BODY + "S1000 M3 M8 M48 M101\nM2\n")) == 2  # one of each group


def test_one_g_code_twice_on_a_line_is_two_of_its_group():
    """LinuxCNC refuses "G0 G0", "G90 G90", "G4 P1 G4" ("Two g codes used from same modal
    group"; grbl too, error 21) but reads "G80 G80"; woodcam read them all."""
    _refused(_BODY + "G0 G0 X2\nM2\n", 4, "G0 G0", "two motion G codes")
    _refused(_BODY + "G00 G0 X2\nM2\n", 4, "G0 G0", "two motion G codes")
    _refused(_BODY + "G90 G90\nM2\n", 4, "G90 G90", "two distance G codes")
    _refused(_BODY + "G4 P1 G4\nM2\n", 4, "G4 G4", "two non-modal G codes")
    _refused(_BODY + "G21 G21\n", 4, "G21 G21", "two units G codes", dialect="grbl")
    assert len(read_gcode(_BODY + "G80 G80\nG0 X2\nM2\n")) == 3


def test_an_n_word_is_read_only_at_the_start_of_a_line():
    """LinuxCNC refuses an N word after another word ("Bad character 'n' used"); grbl reads it
    anywhere on the line, once (error 25 twice). woodcam read N anywhere in every dialect."""
    rule = "N word.* in the middle of a line"
    _refused(_BODY + "G1 X2 F100 N5\nM2\n", 4, "N5", rule)
    _refused(_BODY + "N5 N6 G1 X2\nM2\n", 4, "N6", rule)
    _refused(_BODY + "N5 #1=2 N6\nM2\n", 4, "N6", rule)
    assert len(read_gcode(_BODY + "N5 G1 X2\n/N6 G1 X3\n n7 g1 x4\nM2\n")) == 5
    assert len(read_gcode(_BODY + "G1 X2 N5\n", dialect="grbl")) == 3
    _refused(_BODY + "N5 G1 X2 N6\n", 4, "N6", "word N twice", dialect="grbl")


def test_an_n_word_is_digits_before_any_comment():
    """LinuxCNC refuses a line number after a comment or a block delete after one ("Bad
    character 'n' used"), and one that is not digits ("Bad format unsigned integer"); woodcam
    read them all. A line that is never reached (an uncalled subroutine) is not refused."""
    _refused(_BODY + "(c) N5 G1 X2\nM2\n", 4, "N", "line number .N word. after a comment")
    _refused(_BODY + "/(c)N5 G1 X2\nM2\n", 4, "N", "after a comment")
    _refused(_BODY + "(c) /G1 X2\nM2\n", 4, "/", "block delete '/' after a comment")
    _refused(_BODY + "(c) N5 o100 sub\nG1 X2\no100 endsub\nM2\n", 4, "N", "after a comment")
    # so do O words, M98 and a returning M99 ("Bad character 'o' used", "Unknown m code used:
    # M98", "EOF seeking o-word"): woodcam ran the call, returned, took the label
    sub = "M30\nO7\nG1 Y1\nM99\n"
    _refused(_BODY + "(c) M98 P7\n" + sub, 4, "M98", "call M98 after a comment")
    _refused(_BODY + "N5 (c) M98 P7\n" + sub, 4, "M98", "call M98 after a comment")
    _refused(_BODY + "M98 P7\n" + sub.replace("M99", "(c) M99"), 8, "M99",
             "return M99 after a comment")
    _refused(_BODY + "M98 P7\nM30\n(c) O7\nM99\n", 4, "M98 P7",
             "the O7 on line 6 follows a comment")
    _refused(_BODY + "(c) O7\nG1 X2\nM2\n", 4, "O7", r"O word \(O7\) after a comment")
    _refused(_BODY + "(c) o1 sub\nG1 X2\no1 endsub\nM2\n", 4, "o1 sub", "after a comment")
    # what LinuxCNC runs: a comment after the word, and the main program's M99 (one pass)
    assert len(read_gcode(_BODY + "M98 (c) P7\n" + sub)) == 3
    assert len(read_gcode(_BODY + "G1 X2\n(c) M99\n").moves) == 3
    for word in ("N-5", "N+5", "N5.", "N.5", "N#1", "N[5]", "N"):
        _refused(_BODY + f"{word} G1 X2\nM2\n", 4, word, "line number must be digits")
    prog = read_gcode(_BODY + "N5 (c) G1 X2\nN6.5 G1 X3\n/ (c) G1 X4\no1 sub\n(c) N7 G1 X9\n"
                      "o1 endsub\nM2\n")
    assert [round(m.end_mm[0]) for m in prog.moves] == [0, 1, 2, 3, 4]
    assert len(read_gcode(_BODY + "(c) N-5 G1 X2\n", dialect="grbl")) == 3


def test_analog_io_words_are_read_and_checked_as_linuxcnc():
    """LinuxCNC reads "M67 E0 Q50" (a laser's power), "M66 P0 L3 Q5" (wait for an input);
    woodcam refused every E word as an axis it lacks and every L beside M66. Their checks as
    LinuxCNC's (each line below checked against its interpreter)."""
    prog = read_gcode(_BODY + "M67 E0 Q50 G1 X2\nM68 E1.5 Q3\nM66 E0 L0\nM66 P0 L3 Q5\n"
                      "M66 P1\nM2\n")
    assert len(prog) == 3
    assert [w.split(": ", 1)[1] for w in prog.warnings] == [
        "M67 (analog output) is not simulated", "M68 (analog output) is not simulated",
        "M66 (wait on input) is not simulated", "M66 (wait on input) is not simulated",
        "M66 (wait on input) is not simulated"]
    for line, word, rule in (("G0 X1 E5", "E5", "E word with no G or M code"),
                             ("M62 P0 E1", "E1", "E word with no G or M code"),
                             ("M66 P0 E1", "P0 E1", "not both"),
                             ("M66 L0", "M66", "needs P .* or E"),
                             ("M66 P-1", "M66", "needs P .* or E"),
                             ("M66 P0 L2", "L2", "needs a timeout Q > 0"),
                             ("M67 Q5", "M67", "needs E"), ("M68 E-1 Q5", "M68", "needs E")):
        _refused(_BODY + line + "\nM2\n", 4, word, rule)
    with pytest.raises(GcodeError, match="unsupported word E"):
        read_gcode(_BODY + "M67 E0 Q5\n", dialect="grbl")


def test_words_no_code_uses_are_refused_and_io_warned():
    for line, word in (("G1 X1 Q2 F100", "Q2"), ("G0 X1 R3", "R3"), ("G1 X1 P5 F100", "P5"),
                       ("G0 X1 L2", "L2"), ("G0 X1 H1", "H1"), ("G0 X1 I2", "I2")):
        with pytest.raises(GcodeError, match=word):
            _ends(line + "\nM2\n")
    prog = read_gcode("G0 X1 Y0 Z0\nM64 P1\nM101\nG1 X2 F100\nM2\n")
    assert [w.split(":")[0] for w in prog.warnings] == ["line 2", "line 3"]


@pytest.mark.parametrize("text", ["G0 X" + "[" * 400 + "1" + "]" * 400, "G0 X[" + "-" * 3000 + "1]",
                                  "G0 X" + "abs[" * 400 + "1" + "]" * 400])
def test_an_expression_nested_too_deep_is_one_error(text):
    """G-code is untrusted input: these were RecursionError tracebacks. (Read as Fanuc's
    control reads them: LinuxCNC refuses a line this long before its expression, 'Command too
    long', as woodcam's linuxcnc dialect does.)"""
    with pytest.raises(GcodeError, match="line 1: .*nested deeper than 100 levels"):
        read_gcode(text + "\n", dialect="fanuc")
    with pytest.raises(GcodeError, match="line 1: .*Command too long"):
        read_gcode(text + "\n")
    assert len(read_gcode("G0 X" + "[" * 50 + "1" + "]" * 50 + "\n")) == 1  # deep but sane


def test_axis_words_without_a_motion_mode_name_why_there_is_none():
    """The linuxcnc dialect starts in G80, as LinuxCNC does (checked against its interpreter in
    test_linuxcnc_oracle.py): a bare X10 first was refused as "G80 cancelled it" though no G80
    was given. grbl's and Fanuc's controls start in G0: there it moves."""
    _refused("G21 G90\nX10\nM2\n", 2, "X10", r"axis words without a motion mode \(LinuxCNC starts in G80, "
             r"without one\); add G0 or G1 to the line")
    _refused("G21 G90\nG1 F100 X1\nG80\nX10\nM2\n", 4, "X10",
             r"axis words without a motion mode \(G80 cancelled it\)")
    for dialect in ("grbl", "fanuc"):
        moves, _ = Interpreter("G21 G90\nX10\nM2\n", dialect=dialect, start_mm=(0, 0, 5)).run()
        assert [m[:3] for m in moves] == [(0, 2, (10.0, 0.0, 5.0))]
        _refused("G21 G90\nG80\nX10\nM2\n", 3, "X10", r"\(G80 cancelled it\)", dialect=dialect)


def test_assigning_the_tool_changer_fault_parameters_is_refused():
    """``#5600 = 3`` was taken and then read 0 (the machine's no-fault value): the assignment
    silently dropped. LinuxCNC does the same (checked in test_linuxcnc_oracle.py); woodcam
    refuses it as it refuses the read-only ones and the params argument's #5600/#5601."""
    for n, what in ((5600, "flag"), (5601, "reason")):
        _refused(f"G21 G90\n#{n} = 3\nG0 X#{n}\nM2\n", 2, f"#{n}",
                 rf"#{n} is the tool changer's fault {what}, which the machine sets .*; use another parameter")
    assert _ends("G0 X#5600 Y#5601 Z1\nM2\n") == [(0, 0, 1)]  # reading them stays 0: no fault


def test_an_o_word_after_a_comment_is_refused_at_the_first_such_line():
    """``o1 call`` ... ``(c) o1 sub`` ... ``(c) o1 endsub``: woodcam took the commented sub for
    one, ran it and refused at its endsub (line 7). LinuxCNC reads no O word after a comment
    (checked in test_linuxcnc_oracle.py): the call finds no sub, refused there naming the
    first commented line; a structure that matches only with the commented lines is refused
    at the first of them; one skipped as text runs, with a warning."""
    _refused(_BODY + "o1 call\nM2\n(c) o1 sub\nG1 X2\n(c) o1 endsub\n", 4, "o1 call",
             r"the o1 on line 6 follows a comment: .* no o1 sub .*; move the comment after the o1")
    _refused(_BODY + "(c) o1 sub\nG1 X2\n(c) o1 endsub\nM2\n", 4, "o1 sub", "after a comment")
    _refused(_BODY + "o1 sub\nG1 X2\n(c) o1 endsub\nG1 X5\nM2\n", 6, "o1 endsub",
             r"without it the O words do not match \(line 4: o1 sub is never closed by an o1 "
             r"endsub: LinuxCNC reads the rest of the file as its definition")
    prog = read_gcode(_BODY + "o1 if [0]\nG1 X2\n(c) o1 else\nG1 X3\no1 endif\nM2\n")
    assert len(prog) == 2 and prog.warnings == [  # the body's two moves: G1 X3 skipped as LinuxCNC does
        "line 6: 'o1 else' follows a comment, so it is no O word (LinuxCNC reads one only as the first "
        "word of its line) and was skipped as text; move the comment after the o1"]


def test_a_structure_error_is_not_blamed_on_an_unrelated_commented_o_word():
    """Sweep h13 item 3: any O-word structure error was refused at the first O word after a
    comment, related or not: an unclosed o7 while was blamed on a commented o5 call (also when
    a commented o7 endwhile explained it). The commented one carrying the label of the line at
    fault takes the blame; else, when the O words match with them read as ones, the first that
    opens or closes one (a call or return matches nothing)."""
    _refused(_BODY + "o1 if [1]\no1 endif\n(c) o5 call\no7 while [1 LT 2]\nG1 X1\nM2\n", 7,
             "o7 while", r"^G-code line 7: 'o7 while': o7 while is never closed; close it$")
    # it matches with the commented lines read as O words: the o7 endwhile is why, not the o5 call
    _refused(_BODY + "o7 while [1 LT 2]\n(c) o5 call\nG1 X1\n(c) o7 endwhile\nM2\n", 7,
             "o7 endwhile", r"without it the O words do not match \(line 4: o7 while is never closed\)")
    _refused(_BODY + "(c) o5 call\no7 while [1 LT 2]\nG1 X1\n(c) o7 endwhile\nM2\n", 7,
             "o7 endwhile", r"without it the O words do not match \(line 5: o7 while is never closed\)")
    # no match either way (o8 if is never closed), but the label at fault is a commented one's
    _refused(_BODY + "o8 if [1]\n(c) o5 call\no7 while [1 LT 2]\nG1 X1\n(c) o7 endwhile\nM2\n", 8,
             "o7 endwhile", r"without it the O words do not match \(line 6: o7 while is never closed\)")


def test_a_call_is_told_of_a_commented_sub_only():
    """Sweep h13 item 4: every kind of commented O word was recorded as why a call finds no
    sub: a call of an undefined o5 after a commented 'o5 call' said "the o5 on line 5 follows
    a comment ... there is no o5 sub"; only a commented 'o5 sub' explains that."""
    _refused(_BODY + "o2 if [0]\n(c) o5 call\no2 endif\no5 call\nM2\n", 7, "o5 call",
             r"^G-code line 7: 'o5 call': subroutine o5 is not defined in this file")
    _refused(_BODY + "o5 call\nM2\n(c) o5 sub\nG1 X2\n(c) o5 endsub\n", 4, "o5 call",
             r"the o5 on line 6 follows a comment: .* no o5 sub")


def _messages(text):
    """The ``(line, message)`` of each operator message ``text`` says, in order."""
    interp = Interpreter(text, start_mm=(0, 0, 0))
    interp.run()
    return interp.messages


def test_a_msg_comment_says_its_message_only_where_linuxcnc_runs_its_line():
    """LinuxCNC keeps a line's last ( ) comment only, and reads no comment of an O-word, M98,
    M99 or O program number line (its flow control); woodcam said every (MSG,...) of every line
    it passed, so an o-word loop's (MSG,...) came once a pass and a sub's header once, where the
    machine shows none (checked against its interpreter in test_linuxcnc_oracle.py)."""
    text = ("o2 sub (MSG,sub line)\n(MSG,in sub)\no2 endsub (MSG,endsub line)\n"
            "o2 call (MSG,call line)\no3 while [#1 lt 1] (MSG,while line)\n#1=1\n"
            "o3 endwhile (MSG,endwhile line)\n(MSG,a) ;(MSG,b)\n(MSG,c) G0 X2 (plain)\n"
            "(plain) (MSG, last)\nM98 P1000 (MSG,m98 line)\nM2\nO1000 (MSG,o1000 line)\n"
            "(MSG,in o1000)\nM99 (MSG,m99 line)\n")
    assert _messages(text) == [(2, "in sub"), (8, "a"), (10, "last"), (14, "in o1000")]


def test_debug_and_print_comments_say_the_parameters_values_where_the_line_runs():
    """LinuxCNC shows (DEBUG,...) as it shows (MSG,...), with each #n and #<name> replaced by
    its value as C's %lf when the line runs (after the line's assignments, before its move;
    each pass of a loop, a sub's locals), and writes (PRINT,...) to its terminal; woodcam read
    both as plain comments and said nothing. Known answers from LinuxCNC 2.9's rs274."""
    text = ("#1=2.5\n#<foo>=3\nG0 X1.25 Y2\n"
            "(DEBUG, x=#<_X> one=#1 foo=#< F o O > bad=#<nope> end)\n"
            "#1=5 G0 X4 (debug,#1 x=#<_x> #5420 ##1 #a # x #2 #1.5)\n"
            "G0 X6 (DEBUG,fast path x=#<_x>)\n"
            "o100 do\n(DEBUG, pass #1)\n#1=[#1+1]\no100 while [#1 LT 7]\n"
            "o2 sub\n(DEBUG,in sub #1 #<loc>)\n#<loc>=4\n(DEBUG,in sub #<loc>)\no2 endsub\n"
            "o2 call [9]\n(DEBUG,after #<loc>)\n"
            "#3=0.0001\n#4=-0.000099\n#5=-0.00015\n#6=[-10**21]\n#7=[10**21]\n"
            "(DEBUG,#3 #4 #5 #6 #7 #5601 #5602 #0)\n"
            "(PRINT, p=#1)\n#5599=0\n(DEBUG,hidden)\n(PRINT,shown #5599)\nM2\n")
    interp = Interpreter(text, start_mm=(0, 0, 0))
    interp.run()
    assert interp.messages == [
        (4, "x=1.250000 one=2.500000 foo=3.000000 bad=###### end"),
        (5, "5.000000 x=1.250000 1.250000 #5.000000 #a # x 0.000000 5.000000.5"),
        (6, "fast path x=4.000000"),
        (8, "pass 5.000000"), (8, "pass 6.000000"),
        (12, "in sub 9.000000 ######"), (14, "in sub 4.000000"), (17, "after ######"),
        (23, "0.000100 0.000000 -0.000150 ###### 1000000000000000000000.000000 0.000000 "
             "###### 0.000000")]
    assert interp.printed == [(24, "p=7.000000"), (27, "shown 0.000000")]
    assert interp.warnings == []


def test_print_comments_are_printed_not_said_to_the_operator():
    """LinuxCNC writes (PRINT,...) to its standard output (rs274's stdout, the terminal the
    machine was started from) and never shows it on the operator's screen, where MSG and DEBUG
    go; woodcam put it among the operator messages with a note ('p=2.000000 (PRINT: LinuxCNC
    writes it to its terminal, not its screen)'). It is Interpreter.printed now, values put in
    as DEBUG's, whatever #5599 says (checked against rs274 in test_linuxcnc_oracle.py)."""
    interp = Interpreter("#1=2\n(MSG,m)\n(PRINT, p=#1)\n#5599=0\n(print,low #<_x>)\n"
                         "(DEBUG,hidden)\nM2\n", start_mm=(1, 0, 0))
    interp.run()
    assert interp.messages == [(2, "m")]
    assert interp.printed == [(3, "p=2.000000"), (5, "low 1.000000")]
    for dialect in ("grbl", "fanuc"):  # a plain comment there
        interp = Interpreter("(PRINT,p)\nG0 X1\n", dialect=dialect)
        interp.run()
        assert interp.printed == interp.messages == []


def test_debug_text_woodcam_cannot_fill_in_is_marked_and_warned():
    """A value woodcam does not know (the tool table's #5401, an unset probe result) shows as
    '#5401?' with a warning; a '#' or '#<name' left open at the end, where LinuxCNC shows left
    over text of an earlier message, ends the text with a warning; grbl and Fanuc read DEBUG as
    a plain comment. (A tool loaded: with none, before the first M6, the entry is 0.)"""
    interp = Interpreter("T1 M6\n(DEBUG,tlo=#5403 z=#5063 end)\n(DEBUG,open #)\n(DEBUG,x #<_x)\nM2\n")
    interp.run()
    assert interp.messages == [(2, "tlo=[#5403: T1's Z offset, from the machine's tool table] "
                                   "z=#5063? end"), (3, "open"), (4, "x")]
    assert [w[0] for w in interp.warnings] == [2, 2, 3, 4]
    assert "#5403, T1's Z offset in the machine's tool table" in interp.warnings[0][1]
    assert "#5063, which woodcam cannot know" in interp.warnings[1][1]
    assert "unfinished parameter '#<_x'" in interp.warnings[3][1]
    for dialect in ("grbl", "fanuc"):
        interp = Interpreter("G0 X1 (DEBUG,x)\n(MSG,m)\n", dialect=dialect)
        interp.run()
        assert interp.messages == [(2, "m")]


def test_a_message_in_a_loop_is_said_every_pass_and_warned_once():
    """A (DEBUG,...)/(PRINT,...) in an o-word loop reading what woodcam cannot know warned on
    every pass: a 1000-pass while loop gave 1000 identical warnings a value. Now each line and
    value is warned once, saying how many times the line ran; the messages stay one a pass, as
    LinuxCNC shows them (do and repeat loops the same)."""
    text = ("T1 M6\n#1=0\no100 while [#1 lt 1000]\n(DEBUG,z=#5403 p=#5063 #5063)\n(PRINT,#1 x #)\n"
            "#1=[#1+1]\no100 endwhile\n"
            "o200 do\n(DEBUG,q=#5063)\n#1=[#1-1]\no200 while [#1 gt 997]\n"
            "o300 repeat [2]\n(PRINT,t=#5401)\no300 endrepeat\n(DEBUG,once #5063)\nM2\n")
    interp = Interpreter(text)
    interp.run()
    assert len(interp.messages) == 1000 + 3 + 1 and len(interp.printed) == 1000 + 2
    assert interp.messages[999] == (4, "z=[#5403: T1's Z offset, from the machine's tool "
                                       "table] p=#5063? #5063?")
    assert interp.printed[999] == (5, "999.000000 x")
    said = [(ln, w.split(",...) ")[1].split(",")[0].split(":")[0]) for ln, w in interp.warnings]
    assert said == [(4, "shows #5403"), (4, "reads #5063"), (5, "ends in an unfinished "
                    "parameter '#'"), (9, "reads #5063"), (13, "shows #5401"), (15, "reads #5063")]
    ran = [re.findall(r"\(warned once; the line ran (\d+) times\)$", w) for _, w in interp.warnings]
    assert ran == [["1000"], ["1000"], ["1000"], ["3"], ["2"], []]



def test_a_warned_line_in_a_loop_is_warned_once_with_its_passes():
    """An I/O M code or a G43 without H in an o-word loop warned on every pass: a 500-pass
    while loop around M62 P1 gave 500 identical warnings. Now each line and text is warned
    once, saying how many times the line ran, as a message's warning is (while and repeat)."""
    text = ("#1=0\no100 while [#1 lt 500]\nM62 P1\nM66 P0 L0\n#1=[#1+1]\no100 endwhile\n"
            "o200 repeat [3]\nG43\no200 endrepeat\nM2\n")
    interp = Interpreter(text)
    interp.run()
    assert [(ln, w.split(" (")[0].split(" without")[0]) for ln, w in interp.warnings] == [
        (3, "M62"), (4, "M66"), (8, "G43")]
    ran = [re.findall(r"\(warned once; the line ran (\d+) times\)$", w) for _, w in interp.warnings]
    assert ran == [["500"], ["500"], ["3"]]
    assert len(read_gcode("G0 X0 Y0 Z5\n" + text).warnings) == 3  # (the public reader too)


def test_the_warnings_not_warned_per_pass_are_one_in_a_100_pass_loop():
    """The warnings interpreter.py appends to its list itself, not through Interpreter.warn
    (the once-per-line-and-text warning with a pass count), are said once in a 100-pass
    o100 while loop: an O word after a comment in a branch not taken (read before the run),
    the G53 moves placed without the machine zero (summed up after it, naming their lines
    once), and a T without M6 (once per tool)."""
    text = ("G0 X0 Y0 Z5\n#1=0\no100 while [#1 lt 100]\nG53 G0 Z-5\nG53 G0 X1\nT2\n"
            "G1 Z-1 F100\no200 if [#1 lt 0]\n(note) o7 if [1]\no200 endif\n#1=[#1+1]\n"
            "o100 endwhile\nM2\n")
    interp = Interpreter(text, start_mm=(0, 0, 10), machine_zero_mm=None)
    interp.run()
    assert [(ln, w.split(" ")[0]) for ln, w in interp.warnings] == [
        (9, "'o7"), (7, "T2"), (4, "G53"), (5, "G53")]
    assert [w.split(":")[0] for _, w in interp.warnings[2:]] == [
        "G53 (machine coordinates) on line(s) 4", "G53 (machine coordinates) on line(s) 5"]

def test_tool_table_entries_in_a_message_say_what_they_are_or_the_users_diameter():
    """LinuxCNC shows the loaded tool's entry of the machine's tool table for #5401-#5413 in a
    DEBUG/PRINT (the table's values, whatever G20; rs274 -t in test_linuxcnc_oracle.py);
    woodcam showed '#5410?' even where the user's tool table gives the tool's diameter, and
    '#5403?' said neither what the value is nor why it is missing. Now #5410 is the user's
    diameter of the loaded tool; any other entry, or a tool the user did not give, says what it
    is, with a warning; an expression still may not read them (the machine's table may
    differ)."""
    text = ("T1 M6\n(DEBUG,d=#5410 z=#5403 o=#5413)\nG20\nT2 M6\n(PRINT,d=#5410 x=#5401)\n"
            "T3 M6\n(DEBUG,d=#5410 front=#5411)\nM2\n")
    interp = Interpreter(text, tool_diameters_mm={1: 6.35, 2: 3, 4: 8})
    interp.run()
    table = "from the machine's tool table]"
    assert interp.messages == [
        (2, f"d=6.350000 z=[#5403: T1's Z offset, {table} o=[#5413: T1's orientation, {table}"),
        (7, f"d=[#5410: T3's diameter, {table} front=[#5411: T3's front angle, {table}")]
    assert interp.printed == [(5, f"d=3.000000 x=[#5401: T2's X offset, {table}")]
    said = [(ln, w.split(",...) shows ")[1].split(",")[0]) for ln, w in interp.warnings]
    assert said == [(2, "#5403"), (2, "#5413"), (5, "#5401"), (7, "#5410"), (7, "#5411")]
    assert "--tool 3=SPEC" in interp.warnings[3][1]
    _refused("T1 M6\nG0 X#5410\nM2\n", 2, "#5410", "#5410 is the loaded tool's offset, "
             "diameter", tool_diameters_mm={1: 6.35})


def test_an_abort_comment_stops_the_program_where_it_runs():
    """LinuxCNC ends the program at a reached (ABORT,...) with its text (parameters put in) as
    the error; woodcam read it as a comment and previewed the moves after it, which the
    machine never makes. One in a branch not taken stops nothing; grbl and Fanuc: a comment."""
    text = ("G0 X1\n#1=3\no1 if [#1 gt 5]\n(ABORT, too big #1)\no1 endif\n"
            "o2 if [#1 gt 2]\n(ABORT, limit #1 over 2)\no2 endif\nG0 X2\nM2\n")
    with pytest.raises(GcodeError) as e:
        Interpreter(text).run()
    assert e.value.line == 7 and "'limit 3.000000 over 2'" in e.value.rule
    for dialect in ("grbl", "fanuc"):
        assert _ends("G0 X1\n(ABORT,x)\nG0 X2\nM2\n", dialect=dialect)[-1][0] == 2


def test_an_endsub_with_another_label_inside_a_sub_returns_from_it_as_in_linuxcnc():
    """LinuxCNC passes over 'o101 sub' to 'o101 endsub' and, when a call reaches an 'o100
    endsub' inside it (a renamed or copied sub), returns from o101 there, with its value, in a
    loop too: the lines after it never run. woodcam refused the program ('endsub without a
    matching o100 sub'); it now runs it as LinuxCNC and warns. Without an o101 endsub at all
    LinuxCNC reads the rest of the file as the definition and runs none of it: refused, saying
    so."""
    text = ("o100 sub\nG1 X1 F100\no100 endsub\no101 sub\no1 while [1]\nG1 X2 F100\n"
            "o100 endsub [7]\no1 endwhile\nG1 X3\no101 endsub [3]\no101 call\nG1 Y#<_value>\n"
            "o100 call\nM2\n")
    moves, warnings = Interpreter(text, start_mm=(0, 0, 0)).run()
    assert [m[2] for m in moves] == [(2, 0, 0), (2, 7, 0), (1, 7, 0)]
    assert [w for w in warnings if "endsub" in w[1]] == [(7, (
        "o100 endsub inside the o101 sub of line 4: LinuxCNC reads it as o101's return (a call "
        "of o101 ends here, its lines after it never run), and so does woodcam; write o101 "
        "return (or fix the label)"))]
    with pytest.raises(GcodeError) as e:
        Interpreter("G1 X1 F100\no100 sub\no100 endsub\no101 sub\nG1 X2\no100 endsub\n"
                    "o101 call\nM2\n").run()
    assert e.value.line == 4 and "reads the rest of the file as its definition" in e.value.rule


def test_a_do_loop_reached_while_skipping_is_run_into_with_a_warning():
    """LinuxCNC skips a false 'o1 if' to the next o1 line; an 'o1 do' there stops the skip and
    the program runs on into it: the body is cut (X3), then the do's 'o1 while' is refused as
    a second use of the label (line 6). Inside an outer do left by a break the program runs to
    the end. woodcam refused at the do line with no cut, also where LinuxCNC runs to the end
    (the same programs against LinuxCNC: test_a_do_loop_reached_while_skipping_runs_as_in_
    linuxcnc)."""
    text = "G1 F100 X1\no1 if [0]\nG1 X2\no1 do\nG1 X3\no1 while [0]\nG1 X4\no1 endif\nG1 X5\nM2\n"
    interp = Interpreter(text, start_mm=(0, 0, 0))
    with pytest.raises(GcodeError, match="duplicate O-word label") as e:
        interp.run()
    assert e.value.line == 6 and [m[2][0] for m in interp.moves] == [1, 3]
    assert any(w[0] == 4 and "stops at this do and runs on into it" in w[1]
               for w in interp.warnings)
    text = ("G1 F100 X1\no1 do\nG1 Y1\no1 break\no1 do\nG1 X3\no1 while [0]\nG1 X4\n"
            "o1 while [0]\nG1 X5\nM2\n")
    assert [e[:2] for e in _ends(text)] == [(1, 0), (1, 1), (3, 1), (4, 1), (5, 1)]
    # an if nested under the label is refused where the skip reads it, as before
    with pytest.raises(GcodeError, match="duplicate O-word label") as e:
        _ends("o1 if [0]\no1 if [1]\no1 endif\no1 endif\nM2\n")
    assert e.value.line == 2


#: (program, end points of its moves from the origin, the line refused or None), as rs274 -g
#: (LinuxCNC 2.9) runs them: the o-word lines (of subs, and closers of labels no if or loop
#: opens) it reads only when the program reaches them or passes over their definition (test_sub_lines_are_refused_where_rs274_refuses_them, in
#: test_linuxcnc_oracle.py, checks the table against rs274 itself).
SUB_LINE_PROGRAMS = [
    # text after 'o100 sub': refused as the definition is passed over ...
    ("o100 sub G1 X9\nG1 X#1 F100\no100 endsub\nG1 X2 F100\nM2\n", [], 1),
    # ... not where a call finds it searching forward
    ("G1 X1 F100\no100 call [2]\nG1 X3\nM2\no100 sub [3]\nG1 X#1\no100 endsub\n",
     [(1, 0, 0), (2, 0, 0), (3, 0, 0)], None),
    # text after an endsub passed over: its [value] is read, the rest left; refused on return
    ("o100 sub\nG1 X#1 F100\no100 endsub [2] G1 X5\nG1 X#<_value> F100\n"
     "G1 Y[#<_value_returned>+4]\nM2\n", [(2, 0, 0), (2, 5, 0)], None),
    ("o100 sub\nG1 X#1 F100\no100 endsub G1 X5\nG1 X[#<_value>+1] F100\n"
     "G1 Y[#<_value_returned>+4]\nM2\n", [(1, 0, 0), (1, 4, 0)], None),
    ("o100 sub\nG1 X#1 F100\no100 endsub [2] G1 X5\nG1 Y1 F100\no100 call [3]\nM2\n",
     [(0, 1, 0), (3, 1, 0)], 3),
    ("o100 sub\nG1 X#1 F100\no100 endsub ]\nG1 Y1 F100\no100 call [3]\nM2\n",
     [(0, 1, 0), (3, 1, 0)], 3),
    # an endsub or return outside every definition: refused only when reached
    ("G1 X1 F100\nM2\no100 endsub\n", [(1, 0, 0)], None),
    ("G1 X1 F100\no1 if [0]\no100 return\no1 endif\nG1 X2\nM2\n", [(1, 0, 0), (2, 0, 0)], None),
    ("G1 X1 F100\no100 endsub\nG1 X2\nM2\n", [(1, 0, 0)], 2),
    ("G1 X1 F100\no1 if [1]\no100 return\no1 endif\nG1 X2\nM2\n", [(1, 0, 0)], 3),
    # a sub defined inside another: refused as the outer one is passed over, at the inner line;
    # a forward call runs through it and returns at its endsub (X4 never cut)
    ("G1 X1 F100\no100 sub\no101 sub\no101 endsub\no100 endsub\nG1 X2\nM2\n", [(1, 0, 0)], 3),
    ("G1 X1 F100\nM2\no100 sub\no101 sub\no101 endsub\no100 endsub\n", [(1, 0, 0)], None),
    ("G1 X1 F100\no100 call [2]\nG1 X3\nM2\no100 sub\nG1 X#1\no101 sub\nG1 X9\no101 endsub\n"
     "G1 X4\no100 endsub\n", [(1, 0, 0), (2, 0, 0), (9, 0, 0), (3, 0, 0)], None),
    # a return in a definition passed over is read as the endsub is, in order: its value set
    # (the endsub's [#<_value>+1] reads 5), one it cannot compute refused there, before the
    # moves after the body; the text after it and a parameter without a value left for a call
    ("o100 sub\nG1 X#1 F100\no100 return [1/0]\no100 endsub\nG1 Y1 F100\no100 call [2]\nM2\n",
     [], 3),
    ("o100 sub\no100 return [5]\no100 endsub [#<_value>+1]\nG1 Y#<_value> F100\nM2\n",
     [(0, 6, 0)], None),
    ("o100 sub\no100 return [2] G1 X9\no100 endsub\nG1 Y1 F100\nM2\n", [(0, 1, 0)], None),
    ("o100 sub\no100 return [#<nope>]\no100 endsub\nG1 Y1 F100\nM2\n", [(0, 1, 0)], None),
    # an endif, else, break ... of a label no if or loop opens: refused when reached ('undefined
    # O-word label'), never after M2 or in a branch not taken, nor in a sub not called
    ("G1 Y1 F100\no5 endif\nG1 X2\nM2\n", [(0, 1, 0)], 2),
    ("G1 Y1 F100\no5 break\nG1 X2\nM2\n", [(0, 1, 0)], 2),
    ("G1 Y1 F100\no1 if [0]\no5 endwhile\no1 endif\nG1 X2\nM2\n", [(0, 1, 0), (2, 1, 0)], None),
    ("G1 Y1 F100\nM2\no5 else\no6 continue\n", [(0, 1, 0)], None),
    ("o100 sub\nG1 X#1 F100\no5 endif\no100 endsub\nG1 Y1 F100\nM2\n", [(0, 1, 0)], None),
    ("o100 sub\nG1 X#1 F100\no5 endif\no100 endsub\nG1 Y1 F100\no100 call [2]\nM2\n",
     [(0, 1, 0), (2, 1, 0)], 3),
    # a sub never closed: nothing after M2 is read; reached, refused at its line (rs274 says
    # 'File ended ...' at the file's last, the line it got to looking for the endsub)
    ("G1 X1 F100\nM2\no100 sub\nG1 X2\n", [(1, 0, 0)], None),
    ("G1 X1 F100\no100 sub\nG1 X2\nM2\n", [(1, 0, 0)], 2),
]


@pytest.mark.parametrize("text, ends, line", SUB_LINE_PROGRAMS)
def test_sub_lines_are_refused_where_linuxcnc_refuses_them(text, ends, line):
    """LinuxCNC reads an o-word sub's lines when the program reaches them or passes over the
    definition, and runs the moves before: woodcam refused an endsub or return outside a
    definition, a sub inside another and a sub never closed before running any line, also
    after M2 or in a branch not taken, where LinuxCNC never reads them; refused text after an
    endsub passed over, which LinuxCNC leaves unread until a call returns there; and ran text
    after 'o100 sub', which LinuxCNC refuses ('Unexpected character after O-word'). Now the
    moves before a refusal are cut and the refused line is LinuxCNC's (rs274 quotes it)."""
    interp = Interpreter(text, start_mm=(0, 0, 0))
    if line is None:
        moves, _ = interp.run()
    else:
        with pytest.raises(GcodeError) as e:
            interp.run()
        assert e.value.line == line, e.value
        moves = interp.moves
    assert [m[2] for m in moves] == ends
