"""Blocks: size, six faces (photo, ring traces, ring map), readers and writers."""

from .block import Block, Face, RingTrace
from .io import block_from_images, read_block, read_block_folder, read_mokume, write_block

__all__ = ["Block", "Face", "RingTrace", "block_from_images", "read_block", "read_block_folder", "read_mokume",
           "write_block"]
