"""Blocks: size, six faces (photo, ring traces, ring map), readers and writers."""

from .block import Block, Face, RingTrace

__all__ = ["Block", "Face", "RingTrace"]
