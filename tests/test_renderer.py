"""The renderer composes registered stages (issue 25): every method is a registered stage object, the
renderer never branches on the method, and a frame's result is its own."""

from __future__ import annotations

import inspect

import numpy as np
import pytest

import warpcaustics as wc
from warpcaustics import pipeline
from warpcaustics.caustics.registry import METHODS
from warpcaustics.caustics.stage import CausticStage
from warpcaustics.config import CausticsMethod

from helpers import CONFIGS

SMALL = {"water.resolution": 32, "caustics.map_resolution": 32, "optics.wavelengths.bins": 3,
         "sun.disk_samples": 2, "caustics.eikonal_resolution": 24, "caustics.wave3d_resolution": 48,
         "caustics.wave3d_cells_per_wavelength": 4}


def test_every_method_is_a_registered_stage():
    """Each ``caustics.method`` value has a CausticStage subclass registered under its own name."""
    assert set(METHODS) == set(CausticsMethod)
    for method, stage in METHODS.items():
        assert issubclass(stage, CausticStage) and stage.name == method.value


def test_the_renderer_has_no_per_method_branch():
    """The pipeline module names no caustics method: it looks the stage up in the registry."""
    source = inspect.getsource(pipeline)
    assert "CausticsMethod" not in source
    for method in CausticsMethod:
        assert f'"{method.value}"' not in source


def _arrays(result) -> dict[str, np.ndarray]:
    """Every array a result holds (its comparison's and its dictionaries' too), copied."""
    out = {}
    for res, tag in ((result, ""), (result.comparison, "comparison.")):
        if res is None:
            continue
        for key, value in vars(res).items():
            if isinstance(value, np.ndarray):
                out[tag + key] = value.copy()
            elif isinstance(value, dict):
                out.update({f"{tag}{key}.{k}": v.copy() for k, v in value.items()
                            if isinstance(v, np.ndarray)})
    return out


@pytest.mark.parametrize("method,extra", [
    ("fluxratio", {"sky.model": "uniform", "sky.diffuse_fraction": 0.2, "sky.directions": 2}),
    ("photons", {"camera.enabled": True, "camera.width": 16, "camera.height": 12,
                 "camera.position_m": [0.0, -5.0, -1.5], "camera.look_at_m": [0.0, 0.0, -3.5]}),
    ("both", {"camera.enabled": True, "camera.width": 16, "camera.height": 12,
              "camera.position_m": [0.0, -5.0, -1.5], "camera.look_at_m": [0.0, 0.0, -3.5]}),
    ("sunmap", {}),
    ("eikonal", {}),
])
def test_a_result_is_not_changed_by_the_next_frame(method, extra):
    """The buffers a stage reuses from pass to pass and frame to frame never show through a
    RenderResult: rendering the next frame leaves the first frame's arrays as they were."""
    scene = wc.load_scene(CONFIGS / "ocean.toml", {**SMALL, "caustics.method": method, **extra})
    renderer = wc.Renderer(scene, device="cpu")
    first = renderer.render(0.0)
    kept = _arrays(first)
    second = renderer.render(0.5)
    assert not np.array_equal(second.floor_irradiance, first.floor_irradiance)  # the sea moved
    for key, value in _arrays(first).items():
        np.testing.assert_array_equal(value, kept[key], err_msg=key)
