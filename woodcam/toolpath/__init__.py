"""Toolpath preview: G-code -> straight moves -> simulated stock (height field) -> mesh.

``read_gcode`` (:mod:`.gcode`), tools and tool tables (:mod:`.tools`), the stock-removal
simulation (:mod:`.simulate`), the result mesh (:mod:`.mesh`) and the exact manifold3d reference
used by tests and benchmarks (:mod:`.reference`). Lengths in mm; the machine frame is the G-code
work frame, the result is in the block frame of ``docs/conventions.md``.
"""

from .gcode import GcodeError, Move, Program, read_gcode
from .mesh import heightfield_mesh
from .simulate import Issue, SimResult, simulate
from .tools import (BallEndMill, BullNoseMill, FlatEndMill, Tool, VBit, load_tool_table,
                    parse_tool_spec)

__all__ = [
    "BallEndMill", "BullNoseMill", "FlatEndMill", "GcodeError", "Issue", "Move", "Program",
    "SimResult", "Tool", "VBit", "heightfield_mesh", "load_tool_table", "parse_tool_spec",
    "read_gcode", "simulate",
]
