"""Random G-code programs for the differential test against LinuxCNC and the fuzzing of the
reader (issue 15): seeded, reproducible, mostly valid (so they exercise geometry, not only
refusals) with a share of refusals (bad arcs, bad words, division by zero...)."""

from __future__ import annotations

import math

import numpy as np


def _num(rng, v):
    """A number as posts write it: 0-4 decimals, sometimes a trailing '.'."""
    if v == round(v):  # integers as posts write them: 12, 12. or 12.000
        return rng.choice([f"{v:.0f}", f"{v:.0f}.", f"{v:.3f}"])
    return f"{v:.{int(rng.integers(3, 6))}f}"  # the values carry at most 3 decimals


def _val(rng, v, params):
    """``v`` as a number or an expression that evaluates to it (LinuxCNC syntax)."""
    r = rng.random()
    if r < 0.6 or not params:
        return _num(rng, v)
    if r < 0.75:
        k, pv = list(params.items())[int(rng.integers(len(params)))]
        return f"[#{k} + {v - pv:.6f}]"
    if r < 0.85:
        return f"[{v * 2:.6f} / 2]"
    if r < 0.93:
        return f"[{v - 3:.6f} + 1 * 3]"
    return f"[{abs(v):.6f} * {'-1' if v < 0 else '1'}]"


def program(seed: int, n_lines: int = 30, *, valid_share: float = 0.9) -> str:
    """One random program of about ``n_lines`` blocks, ending with M2."""
    rng = np.random.default_rng(seed)
    out = ["G21 G90 G17", "F600"]
    pos = np.array([0.0, 0.0, 10.0])  # program coordinates (G90, mm, no offsets)
    params: dict[int, float] = {}
    plane = 17
    for _ in range(n_lines):
        r = rng.random()
        if r < 0.25:
            tgt = pos.copy()
            axes = [a for a in range(3) if rng.random() < 0.6] or [int(rng.integers(3))]
            for a in axes:
                tgt[a] = round(float(rng.uniform(-20, 80)), 3)
            words = " ".join(f"{'XYZ'[a]}{_val(rng, tgt[a], params)}" for a in axes)
            out.append(f"G{int(rng.integers(0, 2))} {words}")
            pos = tgt
        elif r < 0.45:  # arc in the current plane with a valid centre
            a1, a2 = {17: (0, 1), 18: (2, 0), 19: (1, 2)}[plane]
            names = {17: "IJ", 18: "KI", 19: "JK"}[plane]
            rad = float(rng.uniform(0.5, 30))
            ang0 = float(rng.uniform(0, 2 * math.pi))
            c = (pos[a1] - rad * math.cos(ang0), pos[a2] - rad * math.sin(ang0))
            ang1 = float(rng.uniform(0, 2 * math.pi))
            end = pos.copy()
            end[a1] = round(c[0] + rad * math.cos(ang1), 4)
            end[a2] = round(c[1] + rad * math.sin(ang1), 4)
            off = (round(c[0] - pos[a1], 4), round(c[1] - pos[a2], 4))
            code = "G2" if rng.random() < 0.5 else "G3"
            ax = "XYZ"
            words = f"{ax[a1]}{end[a1]:.4f} {ax[a2]}{end[a2]:.4f}"
            if rng.random() < 0.3:  # helix
                an = 3 - a1 - a2
                end[an] = round(float(pos[an] - rng.uniform(0, 3)), 3)
                words += f" {ax[an]}{end[an]:.3f}"
            if rng.random() < 0.3:
                rr = math.hypot(end[a1] - pos[a1], end[a2] - pos[a2])
                out.append(f"{code} {words} R{(rad if rng.random() < 0.5 else -rad):.4f}"
                           if rr > 1e-3 else f"{code} {words} {names[0]}{off[0]} "
                           f"{names[1]}{off[1]}")
            else:
                p = f" P{int(rng.integers(2, 4))}" if rng.random() < 0.1 else ""
                out.append(f"{code} {words} {names[0]}{off[0]} {names[1]}{off[1]}{p}")
            pos = end
        elif r < 0.55:
            k = int(rng.integers(1, 40))
            v = round(float(rng.uniform(-50, 50)), 3)
            params[k] = v
            out.append(f"#{k} = {v}")
        elif r < 0.6:
            plane = int(rng.choice([17, 18, 19]))
            out.append(f"G{plane}")
        elif r < 0.66:  # drilling cycle at an absolute point in G17
            x, y = (round(float(v), 2) for v in rng.uniform(0, 80, 2))
            rr = round(float(rng.uniform(0.5, 5)), 2)
            z = round(float(rng.uniform(-15, -1)), 2)
            code = rng.choice(["G81", "G82 P0.1", "G83 Q2.5", "G73 Q1.5", "G85", "G89 P0.2"])
            ret = rng.choice(["G98", "G99"])
            out.append(f"G17 {ret} {code} X{x} Y{y} Z{z} R{rr}")
            out.append("G80")
            plane = 17
            pos = np.array([x, y, round(float(rng.uniform(5, 10)), 3)])
            out.append(f"G0 Z{pos[2]}")
        elif r < 0.7:  # work offsets / G92 round trip, then an absolute re-position
            choice = rng.integers(4)
            if choice == 0:
                n = int(rng.integers(1, 10))
                out.append(f"G10 L2 P{n} X{rng.uniform(-10, 10):.3f} Y{rng.uniform(-10, 10):.3f}")
            elif choice == 1:
                out.append(rng.choice(["G54", "G55", "G56", "G57", "G58", "G59", "G59.1",
                                       "G59.2", "G59.3"]))
            elif choice == 2:
                out.append(f"G92 X{rng.uniform(-5, 5):.3f}")
            else:
                out.append(rng.choice(["G92.1", "G92.2", "G92.3"]))
            pos = np.round(rng.uniform(0, 60, 3), 3)
            out.append(f"G0 X{pos[0]} Y{pos[1]} Z{pos[2]}")
        elif r < 0.74:
            out.append(rng.choice(["G91 G0 X5 Y-3", "G91 G1 Z-1.5", "G91 G1 X-2.5 Y2.5"]))
            out.append("G90")
            pos = pos + {"G91 G0 X5 Y-3": [5, -3, 0], "G91 G1 Z-1.5": [0, 0, -1.5],
                         "G91 G1 X-2.5 Y2.5": [-2.5, 2.5, 0]}[out[-2]]
        elif r < 0.78:
            out.append(rng.choice(["M3 S12000", "M5", "M8", "M9", "T2 M6", "G4 P0.1",
                                   "G61", "G64 P0.01", "(a comment)", "; a comment",
                                   "G43 H2", "G49", "G94"]))
            if out[-1] == "T2 M6":  # LinuxCNC's preview module forgets arc ends at M6
                out.append(f"G0 X{pos[0]:.4f} Y{pos[1]:.4f} Z{pos[2]:.4f}")  # (test_linuxcnc_
                # preview_stale_position_after_m6): every axis stated again
        elif r < 0.8:
            label = int(rng.integers(100, 999))
            out.append(f"o{label} if [#{int(rng.integers(1, 5))} GT 0]")
            out.append(f"G0 Z{pos[2]:.3f}")
            out.append(f"o{label} endif")
        if rng.random() > valid_share:  # a fault: refusal expected from both interpreters
            out.append(rng.choice(["G1 X[1/0]", "G2 X10 Y0 I1 J0", "G1 A5", "G1 X1 X2",
                                   "G0 X1 R5", "#<undefined_name_x>=[#<nope>]", "G1 X1 Q-2",
                                   "G83 X1 Y1 Z-3 R1 Q0", "G1 X[SQRT[-1]]", "M123"]))
    out.append("M2")
    return "\n".join(out) + "\n"


def oword_program(seed: int, n_blocks: int = 8, *, reuse: float = 0.0) -> str:
    """One random program of O-word control flow (LinuxCNC dialect): subroutines with
    arguments and return values, nested while/do/repeat loops with break and continue (in
    while/do only, as LinuxCNC), if/elseif/else, numbered, local and global named parameters,
    and moves (G0/G1/G2/G3, a canned cycle) whose words read them. Labels are unique and every
    loop is bounded, so LinuxCNC and woodcam both run it to the end unless a move is invalid.

    ``reuse`` > 0: each if, while and repeat takes one of the labels o10-o13 with that
    probability (do loops keep their own: a second do's test would jump back to the first),
    a subroutine repeats an earlier one's label with a quarter of it, and with 0.3 the
    subroutines follow the M2 (found by the calls searching forward); LinuxCNC refuses a label
    reused within one subroutine or the main program when it is reached."""
    rng = np.random.default_rng(seed)
    labels = iter(range(100, 10_000))

    def label() -> int:
        """An if/while/repeat label: new, or with ``reuse`` one of o10-o13."""
        if reuse and rng.random() < reuse:
            return int(rng.integers(10, 14))
        return next(labels)
    subs: list[tuple[int, int]] = []  # (label, number of arguments)
    head = ["G21 G90 G17 F500", "G0 X0 Y0 Z10", "#1 = 2", "#<_g> = 1.5"]

    def val() -> str:
        """A value: a number or an expression over #1, #2, #<_g>, #<k> (always defined)."""
        r = rng.random()
        a = f"{rng.uniform(-5, 20):.3f}"
        if r < 0.4:
            return a
        if r < 0.6:
            return f"[#1 * {rng.uniform(0.5, 3):.2f} + {a}]"
        if r < 0.75:
            return f"[#<_g> + {a}]"
        if r < 0.88:
            return f"[[#2 MOD 4] + {a}]"
        return f"[ABS[{a}] - #<_x> * 0]"

    def cond() -> str:
        return rng.choice([f"[#1 LT {rng.integers(1, 6)}]", f"[#2 GT {rng.integers(0, 4)}]",
                           "[#<_g> EQ 1.5]", f"[[#1 MOD 2] EQ {rng.integers(0, 2)}]",
                           f"[#<_x> GE {rng.integers(0, 10)}]"])

    def move() -> list[str]:
        r = rng.random()
        if r < 0.45:
            return [f"G{rng.integers(0, 2)} X{val()} Y{val()}"]
        if r < 0.6:
            return [f"G1 Z{rng.uniform(-2, 5):.3f}"]
        if r < 0.8:  # a full circle (I/J only) or a half circle, both always valid
            rad = rng.uniform(1, 5)
            code = rng.choice(["G2", "G3"])
            if rng.random() < 0.5:
                return [f"{code} I{rad:.3f} J0"]
            return [f"{code} X[#<_x> + {2 * rad:.3f}] I{rad:.3f} J0"]
        if r < 0.9:
            return ["#2 = [#2 + 1]", f"#<k> = {val()}", "G0 X#<k> Y[#2 * 0.5]"]
        return [f"G{rng.choice([98, 99])} G81 X{val()} Y{val()} Z-1 R2", "G80", "G0 Z5"]

    def block(depth: int, loop: int | None) -> list[str]:
        r = rng.random()
        if depth >= 3 or r < 0.35:
            return move()
        lab = label() if r < 0.62 or 0.72 <= r < 0.82 else next(labels)  # (a do: its own)
        if r < 0.5:  # if / elseif / else
            out = [f"o{lab} if {cond()}"] + block(depth + 1, loop)
            if rng.random() < 0.5:
                out += [f"o{lab} elseif {cond()}"] + block(depth + 1, loop)
            if rng.random() < 0.5:
                out += [f"o{lab} else"] + block(depth + 1, loop)
            return out + [f"o{lab} endif"]
        if r < 0.62:  # while with its own counter
            c = f"#<c{lab}>"
            body = [f"{c} = [{c} + 1]"] + block(depth + 1, lab)
            if rng.random() < 0.5:  # break or continue inside an if inside the loop
                k = label()
                body += [f"o{k} if [{c} EQ {rng.integers(1, 3)}]",
                         f"o{lab} {rng.choice(['break', 'continue'])}", f"o{k} endif"]
            body += block(depth + 1, lab)
            return [f"{c} = 0", f"o{lab} while [{c} LT {rng.integers(1, 4)}]"] + body + [
                f"o{lab} endwhile"]
        if r < 0.72:  # do / while
            c = f"#<c{lab}>"
            return ([f"{c} = 0", f"o{lab} do", f"{c} = [{c} + 1]"] + block(depth + 1, lab)
                    + [f"o{lab} while [{c} LT {rng.integers(1, 3)}]"])
        if r < 0.82:
            return [f"o{lab} repeat [{rng.integers(0, 3)}]"] + block(depth + 1, None) + [
                f"o{lab} endrepeat"]
        if subs:
            s, n = subs[int(rng.integers(len(subs)))]
            args = " ".join(f"[{val()}]" for _ in range(n))
            out = [f"o{s} call {args}".rstrip()]
            if rng.random() < 0.5:
                out.append("G0 X[#<_value> + 1] Y#<_value_returned>")
            return out
        return move()

    defs: list[str] = []
    for _ in range(int(rng.integers(0, 3))):  # subroutines, defined before the main program
        lab, n = next(labels), int(rng.integers(0, 3))
        if subs and reuse and rng.random() < reuse / 4:  # a second definition of a label
            lab = subs[int(rng.integers(len(subs)))][0]
        body = [f"#<a> = [#1 + {rng.uniform(0, 3):.2f}]"] if n else []
        for _ in range(int(rng.integers(1, 3))):
            body += block(1, None)
        if rng.random() < 0.3:
            k = label()
            body += [f"o{k} if [#<a> GT 10]" if n else f"o{k} if [#1 GT 1]",
                     f"o{lab} return [{rng.integers(1, 9)}]", f"o{k} endif"]
        end = f"o{lab} endsub [{val()}]" if rng.random() < 0.5 else f"o{lab} endsub"
        defs += [f"o{lab} sub"] + ["  " + b for b in body] + [end]
        subs.append((lab, n))
    main: list[str] = []
    for _ in range(n_blocks):
        main += block(0, None)
    if reuse and rng.random() < 0.3:
        return "\n".join(head + main + ["M2"] + defs) + "\n"
    return "\n".join(defs + head + main + ["M2"]) + "\n"
