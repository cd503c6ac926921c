"""The crest-shading march steps over blocks of cells whose highest vertex its ray already clears
(``kernels/optics/refract.py``): the same visibility, to the bit, as the step-by-step march it
replaced (kept in ``benchmarks/shading.py`` as the benchmark's baseline), on periodic seas (a
choppy one), on grids that are not a multiple of the blocks and in a walled pool, at every sun from
the zenith to grazing. (Periodic seas are shaded by the sweep, ``tests/test_horizon.py``; the march
shades walled water and is the sweep's baseline.)"""

import numpy as np
import pytest

import warpcaustics as wc
from warpcaustics.optics.refraction import height_blocks, height_range, march_visibility
from warpcaustics.pipeline import Renderer

from benchmarks.shading import direction, stepwise
from helpers import CONFIGS

SURFACES = {
    "field sea, 128² over 8 m": (CONFIGS / "field/gernez2009.toml", {"water.resolution": 128,
                                                                     "water.extent_m": 8.0}, 0.0),
    "procedural waves, 100²": (CONFIGS / "procedural.toml", {"water.resolution": 100}, 1.3),
    "choppy sea, 128² over 4 m": (CONFIGS / "ocean.toml", {"water.resolution": 128, "water.extent_m": 4.0,
                                                           "water.choppiness": 1.0}, 0.7),
    "walled pool with drops, 96²": (CONFIGS / "pool.toml", {"water.resolution": 96}, 0.4),
}


@pytest.mark.parametrize("name", list(SURFACES))
def test_blocks_give_the_stepwise_visibility_to_the_bit(name, device):
    path, overrides, time_s = SURFACES[name]
    surface = Renderer(wc.load_scene(path, overrides), device).water.at(time_s)
    _, highest = height_range(surface, device)
    blocks = height_blocks(surface, device)
    shaded = 0
    for zenith in (0.0, 30.0, 60.0, 75.0, 84.0, 88.0):
        for azimuth in (0.0, 30.0, 90.0, 135.0, 250.0):
            d = direction(zenith, azimuth)
            fast = march_visibility(surface, d, highest, device, blocks=blocks).numpy()
            np.testing.assert_array_equal(fast, stepwise(surface, d, highest, device).numpy(),
                                          err_msg=f"{name}: zenith {zenith}°, azimuth {azimuth}°")
            shaded += int((fast == 0.0).sum())
    assert shaded > 0  # the low suns are shaded somewhere: the comparison is not of all-ones maps
