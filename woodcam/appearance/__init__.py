"""Wood colour: the fast colour-map model, the neural colour volumes learnt from a block's photos
(seed 000, section 3.3) and orientation-dependent blending (eq. 10)."""

from .colormap import SPECIES, ColorMapAppearance, Species, get_species
from .neural import (
    AppearanceFallbackWarning, NeuralAppearance, NoPhotosError, block_appearance, fit_neural_appearance,
)
from .orientation import axis_weights, blend_axis_colors
from .wood import Wood

__all__ = ["SPECIES", "AppearanceFallbackWarning", "ColorMapAppearance", "NeuralAppearance",
           "NoPhotosError", "Species", "Wood", "axis_weights", "blend_axis_colors", "block_appearance",
           "fit_neural_appearance", "get_species"]
