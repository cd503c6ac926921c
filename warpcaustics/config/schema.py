"""The whole configuration: one frozen dataclass whose fields are the sections."""

from __future__ import annotations

import enum
from dataclasses import dataclass, field

from warpcaustics.config.caustics import CausticsConfig
from warpcaustics.config.light import SkyConfig, SunConfig
from warpcaustics.config.optics import OpticsConfig
from warpcaustics.config.output import OutputConfig, StatsConfig
from warpcaustics.config.scene import CameraConfig, FloorConfig, ReceiverConfig
from warpcaustics.config.water import WaterConfig


class DeviceChoice(str, enum.Enum):
    AUTO = "auto"
    CPU = "cpu"
    CUDA = "cuda"


@dataclass(frozen=True)
class Config:
    water: WaterConfig = field(default_factory=WaterConfig)
    """The water surface."""
    floor: FloorConfig = field(default_factory=FloorConfig)
    """The receiving floor."""
    sun: SunConfig = field(default_factory=SunConfig)
    """The sun."""
    optics: OpticsConfig = field(default_factory=OpticsConfig)
    """Water optics and spectral sampling."""
    caustics: CausticsConfig = field(default_factory=CausticsConfig)
    """Caustics method and map."""
    receivers: tuple[ReceiverConfig, ...] = ()
    """Meshes under the water that receive caustics: ``[[receivers]]`` tables (``photons`` only)."""
    camera: CameraConfig = field(default_factory=CameraConfig)
    """A pinhole camera under the water (``photons`` only)."""
    output: OutputConfig = field(default_factory=OutputConfig)
    """What is written."""
    stats: StatsConfig = field(default_factory=StatsConfig)
    """Irradiance statistics reported in run.json."""
    sky: SkyConfig = field(default_factory=SkyConfig)
    """Skylight."""
    device: DeviceChoice = DeviceChoice.AUTO
    """``auto`` (CUDA when available, else CPU), ``cpu`` or ``cuda``."""

    @property
    def map_window(self) -> tuple[float, tuple[float, float]]:
        """(side [m], centre (x, y) [m]) of the floor map: ``caustics.map_extent_m``'s window, or the
        whole water patch about the origin."""
        c = self.caustics
        if c.map_extent_m:
            return c.map_extent_m, (float(c.map_center_m[0]), float(c.map_center_m[1]))
        return self.water.extent_m, (0.0, 0.0)
