"""Packaging: every subpackage is listed in pyproject, and every shipped config renders."""

import sys
from pathlib import Path

import pytest

import warpcaustics as wc

from helpers import CONFIGS, ROOT

if sys.version_info >= (3, 11):
    import tomllib
else:  # pragma: no cover
    import tomli as tomllib


def test_every_subpackage_is_listed():
    """An unlisted subpackage would silently drop out of the wheel."""
    setup = tomllib.loads((ROOT / "pyproject.toml").read_text())["tool"]["setuptools"]
    listed = set(setup["packages"])
    def packages(folder: Path, name: str) -> set[str]:
        return {".".join([name, *p.parent.relative_to(folder).parts]) for p in folder.rglob("__init__.py")}

    found = packages(ROOT / "warpcaustics", "warpcaustics")
    found |= packages(ROOT / "kernels", "warpcaustics.kernels")
    assert found == listed
    assert setup["package-dir"]["warpcaustics.kernels"] == "kernels"


def test_kernels_import_as_subpackage():
    """Device code is reached as warpcaustics.kernels, never as a top-level 'kernels' module."""
    from warpcaustics.kernels.caustics import fluxratio as floor

    assert floor.__name__ == "warpcaustics.kernels.caustics.fluxratio"
    assert "kernels" not in sys.modules


@pytest.mark.parametrize("config", sorted(CONFIGS.glob("*.toml")), ids=lambda p: p.name)
def test_shipped_configs_render(config, tmp_path):
    """Each file in configs/ validates and renders (at a reduced size) with flux conserved; a study
    file runs its study (at a reduced size)."""
    if "scene" in tomllib.loads(config.read_text()):
        import dataclasses

        from warpcaustics.batch.study import load_study, run_study

        pytest.importorskip("matplotlib")
        study = load_study(config)
        small = dataclasses.replace(study, depths_m=study.depths_m[:2], overrides={
            "water.resolution": 32, "caustics.map_resolution": 32, "optics.wavelengths.bins": 4})
        paths = run_study(small, tmp_path, device="cpu")
        assert all(p.exists() for p in paths.values())
        return
    overrides = {"caustics.map_resolution": 64, "optics.wavelengths.bins": 4}
    shipped = wc.load_scene(config).config
    if shipped.water.model.value != "heightfield":
        overrides["water.resolution"] = 32
    if shipped.camera.enabled:  # a quarter of the picture each way: 47 s -> 5 s for above_water.toml
        overrides.update({"camera.width": 120, "camera.height": 80})
    result = wc.render(wc.load_scene(config, overrides), device="cpu")
    assert result.floor_irradiance.shape == (4, 64, 64)
    assert (result.floor_irradiance >= 0).all() and result.floor_flux_w_nm.min() > 0


def test_every_config_key_is_documented():
    """docs/config.md names every key of the configuration (drops' fields under `water.drops`)."""
    from warpcaustics.config import all_keys

    doc = (ROOT / "docs" / "config.md").read_text()
    assert [k for k in all_keys() if f"`{k.split('[]')[0]}" not in doc] == []
