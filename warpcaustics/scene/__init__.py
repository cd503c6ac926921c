"""A validated scene: the configuration plus what it refers to (a height-field file)."""

from __future__ import annotations

import dataclasses
import functools
import math
import os
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from warpcaustics.config import (
    Config,
    FloorShape,
    SkyModel,
    SkySampling,
    WaterModel,
    config_from_dict,
    read_toml,
)
from warpcaustics.errors import ConfigError
from warpcaustics.optics.sky import cie_relative_radiance, cie_sky_type, stratified_hemisphere
from warpcaustics.optics.sky_cells import cell_key, cell_shares
from warpcaustics.optics.spectra import bins_for, refractive_index
from warpcaustics.scene.heights import DEFAULT_RESOLUTION, load_heights
from warpcaustics.scene.receivers import load_floor_relief, load_receiver_mesh, receiver_albedos


@dataclass(frozen=True)
class Scene:
    """Everything a render needs besides time and device; build it with :func:`load_scene`."""

    config: Config
    base_dir: Path = field(default_factory=Path.cwd)
    """Folder that relative paths in the config start from."""
    heights: np.ndarray | None = field(default=None, repr=False, compare=False)
    """``water.file``'s heights [m] for ``water.model = "heightfield"``."""
    source: str | None = None
    """The file the scene came from, if any."""
    floor_relief: np.ndarray | None = field(default=None, repr=False, compare=False)
    """``floor.file``'s relief [m] for ``floor.shape = "file"``."""
    receiver_meshes: tuple = field(default=(), repr=False, compare=False)
    """The ``[[receivers]]`` meshes in world space (:class:`warpcaustics.scene.receivers.TriangleMesh`)."""

    @property
    def water_resolution(self) -> int:
        return self.config.water.resolution

    @property
    def sky_resolution(self) -> int:
        """Vertices a side of the surface the sky's directions are refracted through: the water's
        own, or ``sky.surface_resolution`` where the sky is in cones over an FFT ocean of a finer grid
        (not for a radiance sensor, ``floor.view_fov_deg``, which traces the sky back through the water's
        own surface)."""
        cfg = self.config
        applies = (cfg.sky.model is not SkyModel.NONE and cfg.sky.sampling is SkySampling.CONES
                   and cfg.water.model is WaterModel.FFT and cfg.sky.surface_resolution
                   and not cfg.floor.view_fov_deg)
        return min(cfg.sky.surface_resolution, self.water_resolution) if applies else self.water_resolution

    def sun_disk_directions(self) -> np.ndarray:
        """(S, 3) unit directions over the sun's disk, each standing for an equal solid angle: a
        sunflower pattern (radius ρ√((i + ½)/h), turns of the golden angle) of h = S/2 points and
        their mirror images through the centre, so the pattern's centroid is the sun's centre and
        the first-order error of the sampling cancels; the centre alone for a point sun."""
        sun = self.config.sun
        s = self.sun_direction
        if sun.angular_diameter_deg <= 0.0:
            return s[None]
        count = max(1, sun.disk_samples // 2)
        radius = 0.5 * math.radians(sun.angular_diameter_deg)
        u = np.cross(s, [0.0, 0.0, 1.0] if abs(s[2]) < 0.9 else [1.0, 0.0, 0.0])
        u /= np.linalg.norm(u)
        v = np.cross(s, u)
        i = np.arange(count) + 0.5
        r = radius * np.sqrt(i / count)
        phi = i * math.pi * (3.0 - math.sqrt(5.0))
        around = np.cos(phi)[:, None] * u + np.sin(phi)[:, None] * v
        around = np.concatenate([around, -around])
        r = np.concatenate([r, r])
        d = np.cos(r)[:, None] * s + np.sin(r)[:, None] * around
        return d / np.linalg.norm(d, axis=1, keepdims=True)

    def sky_directions(self, rng: np.random.Generator | None = None) -> tuple[np.ndarray, np.ndarray]:
        """(K, 3) unit directions towards the sky and (K,) the share of the sky's horizontal
        irradiance each carries on a plane perpendicular to it: cosine-weighted stratified samples
        (sinθ = √((j + ½)/K), turns of the golden angle), each standing for an equal part of the
        horizontal irradiance of a uniform sky, so it brings L_j / Σ L of it, L_j the sky's relative
        radiance there (1 for ``uniform``: 1/(K cosθ) on its perpendicular plane; the CIE type's
        L/L_zenith around the sun for ``cie``, ``cie_clear``). The shares' horizontal parts sum to 1.

        With ``rng`` (``sky.sampling = "halves"``): two such patterns of K/2 directions, each with its
        own random offset u in its strata (sinθ = √((j + u)/(K/2))) and turn φ₀ about the zenith,
        interleaved (the even-numbered directions are the first). Every direction is then
        cosine-distributed over the hemisphere and, for a CIE sky, brings L_j / (K L̄) with L̄ the
        sky's cosine-weighted mean radiance (rather than over the drawn directions' sum, which
        would tie the halves), so each half is an unbiased estimate of the sky's continuum and the
        two halves' errors are independent (their shares' horizontal parts sum to ½ each in
        expectation; exactly for ``uniform``).

        With ``sky.sampling = "cones"`` each direction stands for its cell of the sky (the
        directions nearest it, :mod:`~warpcaustics.optics.sky_cells`) and brings the cell's light:
        what the cell transmits through still water, over the direction's own transmittance
        (:func:`~warpcaustics.optics.sky_cells.cell_shares`), not its own radiance; those shares'
        horizontal parts sum to 1 within a few per cent."""
        sky = self.config.sky
        count = sky.directions
        if rng is None:
            d = stratified_hemisphere(count, 0.5, 0.0)
        else:
            d = np.empty((count, 3))
            for half in range(2):
                d[half::2] = stratified_hemisphere(count // 2, rng.random(), 2.0 * math.pi * rng.random())
        cos_t = d[:, 2]
        sky_type = cie_sky_type(sky)
        if rng is None and sky.sampling is SkySampling.CONES:
            # the first bin's index, as SkyCones (caustics/sky_cones.py) spreads the cells with it
            ior = float(refractive_index(self.config.optics, bins_for(self.config.optics))[0])
            return d, cell_shares(cell_key(d), sky_type, cell_key(self.sun_direction), ior) / cos_t
        if sky_type is not None:
            radiance = cie_relative_radiance(sky_type, d, self.sun_direction)
            if rng is None:
                return d, radiance / (radiance.sum() * cos_t)
            # each half on its own: L_j over the sky's cosine-weighted mean radiance, so that
            # neither half's shares depend on the other's
            mean = _cie_mean_radiance(sky_type, tuple(float(x) for x in self.sun_direction))
            return d, radiance / (count * mean * cos_t)
        return d, 1.0 / (count * cos_t)

    def sky_irradiance(self, sun_irradiance: np.ndarray) -> np.ndarray:
        """(K,) the sky's horizontal spectral irradiance [W m⁻² nm⁻¹]: over the render's bins it is
        ``sky.diffuse_fraction`` f of the global horizontal irradiance, the sun's direct beam
        E_sun sin(elevation) the rest, so ∫E_sky = f/(1 − f) × ∫ that beam; its shape is
        ``sky.spectrum``'s (the diffuse part of ASTM G173-03, or the sun's own)."""
        from warpcaustics.config import SkySpectrum

        sky = self.config.sky
        f = sky.diffuse_fraction
        elevation = math.radians(self.config.sun.elevation_deg)
        beam = np.asarray(sun_irradiance, np.float64) * math.sin(elevation)
        if sky.spectrum is SkySpectrum.SUN:
            return f / (1.0 - f) * beam
        from warpcaustics.optics import spectra

        bins = spectra.bins_for(self.config.optics)
        shape = spectra.sky_diffuse_shape(bins)
        widths = bins.widths_nm
        return f / (1.0 - f) * float(np.sum(beam * widths)) * shape / float(np.sum(shape * widths))

    @property
    def sun_direction(self) -> np.ndarray:
        """Unit vector towards the sun (z up; azimuth from +x towards +y)."""
        el = math.radians(self.config.sun.elevation_deg)
        az = math.radians(self.config.sun.azimuth_deg)
        return np.array([math.cos(el) * math.cos(az), math.cos(el) * math.sin(az), math.sin(el)])


def scene_from_config(cfg: Config, base_dir: Path, source: str | None = None) -> Scene:
    """Load what the config refers to and fill in ``water.resolution`` (file shape or default)."""
    heights = None
    n = cfg.water.resolution or DEFAULT_RESOLUTION
    if cfg.water.model is WaterModel.HEIGHTFIELD:
        heights = load_heights(cfg.water.file, base_dir, cfg.water.resolution)
        n = heights.shape[0]
    cfg = dataclasses.replace(cfg, water=dataclasses.replace(cfg.water, resolution=n))
    _check_spectral_data(cfg, base_dir)
    relief = None
    if cfg.floor.shape is FloorShape.FILE:
        relief = load_floor_relief(cfg.floor.file, base_dir)
    meshes = tuple(load_receiver_mesh(r, base_dir, f"receivers[{i}]") for i, r in enumerate(cfg.receivers))
    from warpcaustics.optics import spectra

    # bad albedo files fail at load, whichever method (only the receiver methods shade with them)
    receiver_albedos(cfg, spectra.bins_for(cfg.optics), base_dir)
    return Scene(cfg, base_dir, heights, source, relief, meshes)


def _check_spectral_data(cfg: Config, base_dir: Path) -> None:
    """Fail at load time, not at render time, when the bins leave the optical data's range or
    the sun's spectrum cannot be read."""
    from warpcaustics.optics import spectra
    from warpcaustics.optics.colour import bin_cmfs

    bins = spectra.bins_for(cfg.optics)
    spectra.sun_irradiance(bins, cfg.sun, base_dir)
    bin_cmfs(bins)  # the colour-matching functions must cover the bins too
    spectra.water_optics(cfg.optics, bins)


def is_file_key(key: str, value) -> bool:
    """Whether a resolved config's ``key`` (its last part) holds the name of a file: ``file``,
    ``albedo_file``, a receiver's ``mesh`` that is not a built-in shape."""
    from warpcaustics.scene.receivers import PRIMITIVES

    return isinstance(value, str) and (key in ("file", "albedo_file")
                                       or key == "mesh" and value not in PRIMITIVES)


def named_files(table, base_dir: Path, prefix: str = "") -> dict[str, Path]:
    """The files a resolved config (``config_to_dict``) names: dotted key (``receivers[0].mesh``) →
    path, a relative one from ``base_dir`` (the config file's folder)."""
    found: dict[str, Path] = {}
    if isinstance(table, list):
        for i, item in enumerate(table):
            found.update(named_files(item, base_dir, f"{prefix.rstrip('.')}[{i}]."))
    elif isinstance(table, dict):
        for key, value in table.items():
            if is_file_key(key, value):
                found[prefix + key] = base_dir / value
            else:
                found.update(named_files(value, base_dir, f"{prefix}{key}."))
    return found


def load_scene(path: str | Path | None = None, overrides: dict[str, Any] | None = None) -> Scene:
    """Read and validate a TOML scene; ``overrides`` maps dotted keys to values.

    ``load_scene(None, {...})`` builds a scene from the defaults and the overrides alone.
    Raises :class:`warpcaustics.errors.ConfigError` with a one-line message on any bad input.
    """
    if path is not None and (not isinstance(path, (str, os.PathLike)) or path == ""):
        raise ConfigError(f"load_scene() takes the path of a .toml file (a str or a Path) or None; got "
                          f"{type(path).__name__} {path!r:.60}")
    if overrides is not None and not isinstance(overrides, Mapping):
        raise ConfigError(f"load_scene() overrides must be a dict of dotted keys, e.g. "
                          f"{{'water.resolution': 64}}; got {type(overrides).__name__} {overrides!r:.60}")
    table = read_toml(path) if path is not None else {}
    cfg = config_from_dict(table, overrides)
    base = Path(path).resolve().parent if path is not None else Path.cwd()
    return scene_from_config(cfg, base, str(path) if path is not None else None)


@functools.lru_cache(maxsize=64)
def _cie_mean_radiance(sky_type: int, sun_direction: tuple[float, float, float]) -> float:
    """A CIE sky's cosine-weighted mean relative radiance over the hemisphere (4096 stratified
    directions), computed once per sky and sun rather than every frame."""
    dense = stratified_hemisphere(4096, 0.5, 0.0)
    return float(cie_relative_radiance(sky_type, dense, np.asarray(sun_direction)).mean())
