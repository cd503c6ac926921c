"""Scene configuration: TOML validated into frozen dataclasses, with dotted overrides.

Every section is a frozen dataclass; a field's docstring says what it is, with its unit in
brackets, and its ``metadata`` carries the allowed range. ``docs/config.md`` documents each key.
Validation errors are one line naming the key, the value, what is allowed and, for unknown keys,
the nearest valid key.

One module per section (``water``, ``optics``, ``light`` for the sun and sky, ``caustics``,
``scene`` for the floor, receivers and camera, ``output`` with the statistics), the whole tree in
``schema``; ``fields`` checks one value, ``checks`` the fields against each other and ``loading``
reads TOML and overrides into a :class:`Config`. Import from here: this package re-exports them.
"""

from __future__ import annotations

from warpcaustics.config.caustics import (
    GREY_METHODS,
    BeamBounds,
    BeamInterpolation,
    CausticsConfig,
    CausticsMethod,
    Intersection,
    PhotonSplat,
    SunMapVariant,
)
from warpcaustics.config.fields import PLANNED_VALUES
from warpcaustics.config.light import SkyConfig, SkyModel, SkySampling, SkySpectrum, SunConfig, SunSpectrum
from warpcaustics.config.loading import all_keys, config_from_dict, config_to_dict, parse_override, read_toml
from warpcaustics.config.optics import (
    BeamSpread,
    JerlovSource,
    OpticsConfig,
    PetzoldStation,
    PhaseFunctionKind,
    Scattering,
    WaterType,
    WavelengthConfig,
)
from warpcaustics.config.output import Colourspace, OutputConfig, ProbeConfig, StatsConfig, WhiteBalance
from warpcaustics.config.scene import CameraConfig, FloorConfig, FloorShape, ReceiverConfig
from warpcaustics.config.schema import Config, DeviceChoice
from warpcaustics.config.water import BodyConfig, DropConfig, WaterConfig, WaterModel, WaterSpectrum

__all__ = [
    "GREY_METHODS",
    "PLANNED_VALUES",
    "BeamBounds",
    "BeamInterpolation",
    "BeamSpread",
    "BodyConfig",
    "CameraConfig",
    "CausticsConfig",
    "CausticsMethod",
    "Colourspace",
    "Config",
    "DeviceChoice",
    "DropConfig",
    "FloorConfig",
    "FloorShape",
    "Intersection",
    "JerlovSource",
    "OpticsConfig",
    "OutputConfig",
    "PetzoldStation",
    "PhotonSplat",
    "PhaseFunctionKind",
    "ProbeConfig",
    "ReceiverConfig",
    "Scattering",
    "SkyConfig",
    "SkyModel",
    "SkySampling",
    "SkySpectrum",
    "StatsConfig",
    "SunConfig",
    "SunMapVariant",
    "SunSpectrum",
    "WaterConfig",
    "WaterModel",
    "WaterSpectrum",
    "WaterType",
    "WavelengthConfig",
    "WhiteBalance",
    "all_keys",
    "config_from_dict",
    "config_to_dict",
    "parse_override",
    "read_toml",
]
