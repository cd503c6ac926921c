"""Crest shading of periodic seas by a sweep along the light's azimuth (``kernels/optics/horizon.py``):
the float64 reference of the same sweep, to rounding; and, against the bilinear surface's own
shading (a float64 march in sixteenth-cell steps), as close as the half-cell march it replaced."""

import numpy as np
import pytest

import warpcaustics as wc
from warpcaustics import reference
from warpcaustics.optics.refraction import height_range, march_visibility, sun_visibility
from warpcaustics.pipeline import Renderer

from benchmarks.shading import direction
from helpers import CONFIGS

SEAS = {
    "field sea, 128² over 8 m": (CONFIGS / "field/gernez2009.toml", {"water.resolution": 128,
                                                                     "water.extent_m": 8.0}, 0.0),
    "choppy sea, 128² over 4 m": (CONFIGS / "ocean.toml", {"water.resolution": 128, "water.extent_m": 4.0,
                                                           "water.choppiness": 1.0}, 0.7),
}


def sea(name: str, device: str):
    path, overrides, time_s = SEAS[name]
    surface = Renderer(wc.load_scene(path, overrides), device).water.at(time_s)
    return surface, height_range(surface, device), surface.positions.numpy().astype(np.float64)


@pytest.mark.parametrize("name", list(SEAS))
def test_the_sweep_is_its_float64_reference(name, device):
    """25 lights from 30° to 88° from the zenith at five azimuths: the kernels' visibility is the
    float64 sweep's but for at most two vertices of a map (float32 rounding where a crest grazes the
    ray; measured: one vertex, in 2 of the 50 maps), and the low lights are shaded somewhere."""
    surface, (lowest, highest), positions = sea(name, device)
    shaded = 0
    for zenith in (30.0, 60.0, 75.0, 84.0, 88.0):
        for azimuth in (0.0, 30.0, 90.0, 135.0, 250.0):
            d = direction(zenith, azimuth)
            seen = sun_visibility(surface, d, highest, device, lowest_m=lowest).numpy()
            expected = reference.sweep_visibility(positions, d, surface.extent_m)
            assert np.sum(seen != expected) <= 2, (zenith, azimuth, np.sum(seen != expected))
            shaded += int((seen == 0.0).sum())
    assert shaded > 0


def test_the_sweep_shades_the_surface_as_closely_as_the_march(device):
    """The field sea under lights 80° and 88° from the zenith at two azimuths (4–67 % of it shaded):
    against the bilinear surface's shading found by a float64 march in 1/16-cell steps, the sweep
    misses no more vertices than 1.5 times the half-cell march does, plus one in 10⁴ (measured 1.04–
    1.29 times, 0.3–0.7 % of the vertices: both look at the same half-cell points along each ray, the
    sweep reading their highest from its lattice)."""
    surface, (_, highest), positions = sea("field sea, 128² over 8 m", device)
    for zenith in (80.0, 88.0):
        for azimuth in (30.0, 200.0):
            d = direction(zenith, azimuth)
            truth = reference.march_visibility(positions, d, surface.extent_m, step_cells=1.0 / 16.0)
            sweep = np.mean(sun_visibility(surface, d, highest, device).numpy() != truth)
            march = np.mean(march_visibility(surface, d, highest, device).numpy() != truth)
            assert 0.0 < truth.mean() < 1.0 and march > 0.0
            assert sweep <= 1.5 * march + 1e-4, (zenith, azimuth, sweep, march)
