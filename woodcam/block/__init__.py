"""Blocks: size, six faces (photo, ring traces, ring map), readers and writers."""

from .block import Block, Face, RingTrace
from .io import read_block, read_mokume, write_block

__all__ = ["Block", "Face", "RingTrace", "read_block", "read_mokume", "write_block"]
