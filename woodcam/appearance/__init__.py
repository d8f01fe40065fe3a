"""Wood colour: the fast colour-map model and orientation-dependent blending (eq. 10)."""

from .colormap import SPECIES, ColorMapAppearance, Species, get_species
from .orientation import axis_weights, blend_axis_colors
from .wood import Wood

__all__ = ["SPECIES", "ColorMapAppearance", "Species", "Wood", "axis_weights",
           "blend_axis_colors", "get_species"]
