"""Water-type study: floor irradiance, caustic contrast and colour by water type, depth and sun.

``warpcaustics study configs/study.toml --out DIR`` renders the base scene for every combination
of ``water_types`` × ``depths_m`` × ``sun_elevations_deg`` and writes ``study.csv``, ``kd.csv``
(the model's effective attenuation against Jerlov's Kd) and ``irradiance_vs_depth.png``.
"""

from __future__ import annotations

import itertools
import warnings
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from warpcaustics.batch.arguments import output_folder, overrides_argument, path_argument
from warpcaustics.config import WaterType, read_toml
from warpcaustics.config.loading import check_key
from warpcaustics.errors import ConfigError
from warpcaustics.io.files import atomic_path, pyplot, write_csv

STUDY_KEYS = {"scene", "water_types", "depths_m", "sun_elevations_deg", "overrides"}
STUDY_SETS = {"optics.water_type": "water_types", "floor.depth_m": "depths_m",
              "sun.elevation_deg": "sun_elevations_deg"}
"""The scene keys a study sets at each render, and the study keys that list their values."""


@dataclass(frozen=True)
class StudyConfig:
    scene: Path
    water_types: tuple[str, ...]
    depths_m: tuple[float, ...]
    sun_elevations_deg: tuple[float, ...]
    overrides: dict


def _numbers(key: str, value, *, positive: bool = False) -> tuple[float, ...]:
    if not isinstance(value, list) or not value or not all(
            isinstance(v, (int, float)) and not isinstance(v, bool) for v in value):
        raise ConfigError(f"study key {key} = {value!r} must be a non-empty list of numbers")
    if positive and any(v <= 0 for v in value):
        raise ConfigError(f"study key {key} = {value!r} must hold positive numbers")
    return tuple(float(v) for v in value)


def _flatten(table: dict, prefix: str = "") -> dict:
    """Nested override tables → dotted keys, so ``[overrides.water]`` sets keys, not the section."""
    out = {}
    for key, value in table.items():
        if isinstance(value, dict):
            out.update(_flatten(value, f"{prefix}{key}."))
        else:
            out[f"{prefix}{key}"] = value
    return out


def load_study(path: str | Path, overrides: dict | None = None) -> StudyConfig:
    """Read a study TOML; errors are one line naming the key. ``overrides`` (the command line's
    ``--set``) join the study's [overrides]."""
    path = path_argument("load_study", "path", path, "a study's .toml file")
    overrides = overrides_argument("load_study", overrides)
    table = read_toml(path)
    for key in table:
        if key not in STUDY_KEYS:
            raise ConfigError(f"unknown study key {key!r}; allowed: {', '.join(sorted(STUDY_KEYS))}")
    for key in ("scene", "water_types", "depths_m", "sun_elevations_deg"):
        if key not in table:
            raise ConfigError(f"study key {key!r} is missing in {str(path)!r}")
    if not isinstance(table["scene"], str) or not table["scene"].strip():
        raise ConfigError(f"study key scene = {table['scene']!r} must be the path of a scene TOML")
    water_types = table["water_types"]
    if not (isinstance(water_types, list) and water_types and all(isinstance(t, str) for t in water_types)):
        raise ConfigError(f"study key water_types = {water_types!r} must be a non-empty list of names")
    allowed = {t.value for t in WaterType}
    for t in water_types:
        if t not in allowed:
            raise ConfigError(f"water_types: {t!r} is not a water type; allowed: "
                              f"{', '.join(sorted(allowed))}")
    depths = _numbers("depths_m", table["depths_m"], positive=True)
    if len(set(depths)) < 2:
        raise ConfigError(f"study key depths_m = {list(depths)} needs at least two different depths (the "
                          "attenuation is fitted over them)")
    elevations = _numbers("sun_elevations_deg", table["sun_elevations_deg"], positive=True)
    for key, values in (("water_types", water_types), ("depths_m", depths),
                        ("sun_elevations_deg", elevations)):
        twice = next((v for i, v in enumerate(values) if v in values[:i]), None)
        if twice is not None:
            raise ConfigError(f"study key {key} lists {twice!r} twice; give each once")
    extra = overrides
    overrides = table.get("overrides", {})
    if not isinstance(overrides, dict):
        raise ConfigError(f"study key overrides = {overrides!r} must be a table of scene keys")
    scene_overrides = {**_flatten(overrides), **(extra or {})}
    for key in scene_overrides:
        check_key(key, "study [overrides]")
        if key in STUDY_SETS:
            raise ConfigError(f"study [overrides] (or --set) sets {key}, which the study sets from its own "
                              f"{STUDY_SETS[key]}; remove it and list the values in {STUDY_SETS[key]}")
    return StudyConfig(path.parent / table["scene"], tuple(water_types), depths, elevations, scene_overrides)


def floor_colour_hex(spectrum: np.ndarray, bins) -> str:
    """sRGB colour (8-bit hex) of a spectrum, scaled so its luminance is 1 before encoding."""
    from warpcaustics.optics import colour as colour_out

    xyz = colour_out.spectral_to_xyz(spectrum[:, None, None], bins)[0, 0]
    rgb = np.clip(colour_out.xyz_to_linear_srgb(xyz / max(xyz[1], 1e-30)), 0.0, None)
    rgb = rgb / max(rgb.max(), 1.0)
    encoded = colour_out.colour_science().cctf_encoding(rgb, function="sRGB")
    return "#" + "".join(f"{int(round(v * 255)):02x}" for v in encoded)


def run_study(study: StudyConfig, out_dir: str | Path, device: str | None = None) -> dict[str, Path]:
    """Render every combination; write study.csv, kd.csv and the plot. Returns the paths."""
    import warpcaustics as wc

    if not isinstance(study, StudyConfig):
        raise ConfigError(f"run_study() takes a study from load_study(path); got {type(study).__name__} "
                          f"{study!r:.60}")
    out_dir = output_folder("out_dir", path_argument("run_study", "out_dir", out_dir, "the output folder"))
    rows, spectra_by = [], {}
    for water_type, elevation, depth in itertools.product(study.water_types, study.sun_elevations_deg,
                                                           study.depths_m):
        scene = wc.load_scene(study.scene, {**study.overrides, "optics.water_type": water_type,
                                            "floor.depth_m": depth, "sun.elevation_deg": elevation})
        result = wc.render(scene, device=device)
        bins = result.bins
        mean = result.floor_irradiance.mean(axis=(1, 2), dtype=np.float64)
        broadband = np.tensordot(result.bin_widths_nm, result.floor_irradiance.astype(np.float64), axes=1)
        spectra_by[(water_type, elevation, depth)] = (mean, result)
        rows.append({"water_type": water_type, "sun_elevation_deg": elevation, "depth_m": depth,
                     "broadband_w_m2": float(np.sum(mean * result.bin_widths_nm)),
                     "caustic_contrast": (float(broadband.std() / broadband.mean()) if broadband.mean() > 0
                                          else float("nan")),  # no light reaches this floor
                     "floor_colour_srgb": floor_colour_hex(mean, bins),
                     **{f"E_{w:.1f}nm": float(e) for w, e in zip(result.wavelengths_nm, mean)}})
    paths = {"study": out_dir / "study.csv", "kd": out_dir / "kd.csv",
             "plot": out_dir / "irradiance_vs_depth.png"}
    write_csv(paths["study"], rows)
    write_csv(paths["kd"], _attenuation_rows(study, spectra_by))
    _plot(study, rows, paths["plot"])
    return paths


def _attenuation_rows(study: StudyConfig, spectra_by: dict) -> list[dict]:
    """Effective attenuation K_eff(λ) = −d ln E / dz (least squares over the depths, per water type
    at the highest sun) beside the beam attenuation c used and Jerlov's Kd (1976) where it exists."""
    import jerlov

    elevation = max(study.sun_elevations_deg)
    rows = []
    for water_type in study.water_types:
        means = np.array([spectra_by[(water_type, elevation, d)][0] for d in study.depths_m])
        result = spectra_by[(water_type, elevation, study.depths_m[0])][1]
        slope = np.polyfit(np.array(study.depths_m), np.log(np.maximum(means, 1e-300)), 1)[0]
        kd = np.full(len(result.wavelengths_nm), np.nan)
        if water_type.startswith("jerlov_"):
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                kd = np.asarray(jerlov.water(water_type.split("_", 1)[1], source="jerlov1976").kd(
                    result.wavelengths_nm), dtype=np.float64)
        for k, wl in enumerate(result.wavelengths_nm):
            rows.append({"water_type": water_type, "sun_elevation_deg": elevation, "wavelength_nm": float(wl),
                         "K_eff_per_m": float(-slope[k]), "c_per_m": float(result.attenuation_per_m[k]),
                         "Kd_jerlov1976_per_m": float(kd[k]),
                         "K_eff_over_Kd": float(-slope[k] / kd[k]) if np.isfinite(kd[k]) else float("nan")})
    return rows


def _plot(study: StudyConfig, rows: list[dict], path: Path) -> None:
    plt = pyplot("the study's plots need")
    elevations = study.sun_elevations_deg
    fig, axes = plt.subplots(1, len(elevations), figsize=(4.2 * len(elevations), 3.6), dpi=110,
                             sharey=True, squeeze=False)
    for ax, elevation in zip(axes[0], elevations):
        for water_type in study.water_types:
            sel = [r for r in rows if r["water_type"] == water_type and r["sun_elevation_deg"] == elevation]
            ax.semilogy([r["depth_m"] for r in sel], [r["broadband_w_m2"] for r in sel], "o-",
                        label=water_type)
        ax.set_title(f"sun {elevation:g}° high")
        ax.set_xlabel("floor depth [m]")
        ax.grid(True, which="both", alpha=0.3)
    axes[0][0].set_ylabel("mean floor irradiance, 400–700 nm [W m⁻²]")
    axes[0][-1].legend(fontsize=8)
    fig.tight_layout()
    with atomic_path(path) as tmp:
        fig.savefig(tmp, format="png")
    plt.close(fig)
