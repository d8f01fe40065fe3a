"""Toolpath preview: G-code -> straight moves -> simulated stock (height field) -> mesh.

``read_gcode`` (:mod:`.gcode`) on the RS274/NGC interpreter (:mod:`.interpreter`; LinuxCNC's
own as the oracle, :mod:`.linuxcnc`), tools and tool tables (:mod:`.tools`), the stock-removal
simulation (:mod:`.simulate`), the result mesh and its planar charts (:mod:`.mesh`), the
deviation from a design part (:mod:`.deviation`) and the exact manifold3d reference used by
tests and benchmarks (:mod:`.reference`). Lengths in mm; the moves are in the G-code (G54)
frame, the result is in the block frame of ``docs/conventions.md``.
"""

from .gcode import GcodeError, Move, Program, read_gcode
from .interpreter import Interpreter
from .mesh import heightfield_mesh
from .simulate import Issue, SimResult, simulate
from .tools import (BallEndMill, BullNoseMill, ChamferMill, FlatEndMill, SnubNoseVBit,
                    TaperedBallMill, Tool, VBit, load_camotics_tools, load_tool_table,
                    parse_tool_spec)

__all__ = [
    "BallEndMill", "BullNoseMill", "ChamferMill", "FlatEndMill", "GcodeError", "Interpreter",
    "Issue", "Move", "Program", "SimResult", "SnubNoseVBit", "TaperedBallMill", "Tool", "VBit",
    "heightfield_mesh", "load_camotics_tools", "load_tool_table", "parse_tool_spec",
    "read_gcode", "simulate",
]
