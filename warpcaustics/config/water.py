"""``[water]``: the water surface model, its drops and the body moving through the pool."""

from __future__ import annotations

import enum
from dataclasses import dataclass, field

from warpcaustics.config.fields import _coordinate, _duration, _length, _positive, _range


class WaterModel(str, enum.Enum):
    FLAT = "flat"
    HEIGHTFIELD = "heightfield"
    FFT = "fft"
    POOL = "pool"
    WAVEPOOL = "wavepool"
    PROCEDURAL = "procedural"


class WaterSpectrum(str, enum.Enum):
    PHILLIPS = "phillips"
    JONSWAP = "jonswap"
    ELFOUHAILY = "elfouhaily"


@dataclass(frozen=True)
class DropConfig:
    time_s: float = field(default=0.0, metadata=_duration())
    """When the drop lands [s]."""
    x_m: float = field(default=0.0, metadata=_coordinate())
    """Where it lands, x [m] (the pool spans ±extent_m/2)."""
    y_m: float = field(default=0.0, metadata=_coordinate())
    """Where it lands, y [m]."""
    radius_m: float = field(default=0.1, metadata=_length(positive=True))
    """Gaussian radius (standard deviation) of the added water [m]."""
    height_m: float = field(default=0.05, metadata=_range(-10.0, 10.0))
    """Peak height of the added (or, if negative, removed) water [m]."""


@dataclass(frozen=True)
class BodyConfig:
    radius_m: float = field(default=0.0, metadata=_length())
    """Radius of a disc-shaped body moving through the ``pool`` [m]; 0 = no body."""
    center_x_m: float = field(default=0.0, metadata=_coordinate())
    """Centre of its circular path, x [m]."""
    center_y_m: float = field(default=0.0, metadata=_coordinate())
    """Centre of its circular path, y [m]."""
    path_radius_m: float = field(default=1.0, metadata=_length())
    """Radius of the circular path [m]."""
    period_s: float = field(default=4.0, metadata=_duration(positive=True))
    """Time for one turn (counter-clockwise seen from above) [s]."""
    response_s: float = field(default=0.02, metadata=_duration(positive=True))
    """Time over which the water under the body takes on its velocity [s]."""


@dataclass(frozen=True)
class WaterConfig:
    model: WaterModel = WaterModel.FFT
    """Surface model: ``flat``, ``heightfield`` (from ``water.file``), ``fft`` (Tessendorf), the walled
    ``pool`` (shallow water) and ``wavepool`` (wave equation), or ``procedural`` (GPU Gems octave
    waves, an open patch that does not tile)."""
    extent_m: float = field(default=16.0, metadata=_length(positive=True))
    """Side L of the square water patch centred at the origin [m]."""
    resolution: int | None = field(default=None, metadata=_range(4, 4096))
    """Vertices per side N (default 256; a heightfield takes N from its file) [-]."""
    file: str | None = None
    """``.npy`` 2-D float array of heights [m], ``h[iy, ix]``, at cell centres; relative paths
    are resolved against the config file's folder."""
    spectrum: WaterSpectrum = WaterSpectrum.PHILLIPS
    """Wave spectrum of the ``fft`` ocean: ``phillips`` (Tessendorf), ``jonswap`` (fetch-limited) or
    ``elfouhaily`` (Elfouhaily et al. 1997: long and short waves, its own spreading)."""
    wind_speed_m_s: float = field(default=4.0, metadata=_positive(60.0))
    """Wind speed at 10 m [m/s]."""
    wind_direction_deg: float = field(default=0.0, metadata=_range(-360.0, 360.0))
    """Direction the wind blows to, from +x towards +y [deg]."""
    phillips_amplitude: float = field(default=1.75e-3, metadata=_positive(1.0))
    """Phillips constant A (dimensionless): height variance = A·π·(V²/g)²/2 over all k."""
    small_wave_m: float = field(default=0.0, metadata=_length())
    """Waves shorter than this are suppressed by exp(-k² l²) (Tessendorf eq. 41) [m]."""
    shortest_wave_m: float = field(default=0.0, metadata=_length())
    """Waves of this wavelength or shorter are dropped from the spectrum (``fft``) [m]; 0 = none: a
    coarse large patch that carries only the waves a finer patch of this side lacks (``warpcaustics
    field gernez2009``'s ``--large-scale``)."""
    fetch_m: float = field(default=100_000.0, metadata=_positive(1.0e7))
    """Distance over which the wind has blown (JONSWAP, Elfouhaily) [m]."""
    jonswap_gamma: float = field(default=3.3, metadata=_range(1.0, 10.0))
    """JONSWAP peak enhancement γ (1 = Pierson–Moskowitz shape) [-]."""
    spreading_s: float = field(default=10.0, metadata=_range(0.0, 1000.0))
    """Exponent s of the cos-2s directional spreading (JONSWAP); larger = narrower [-]."""
    depth_m: float = field(default=0.0, metadata=_length())
    """Depth of the sea the ``fft`` ocean's waves feel (finite-depth dispersion, JONSWAP's k–ω
    mapping) [m]; 0 = ``floor.depth_m``. A floor that stands for a sensor plane in open water sets
    the sea's own depth here (the field configs: deep water)."""
    choppiness: float = field(default=0.0, metadata=_range(0.0, 5.0))
    """Strength λ of the choppy horizontal displacement (Tessendorf eq. 29) [-]; 0 = none."""
    viscosity_m2_s: float = field(default=1.0e-4, metadata=_range(0.0, 1.0))
    """Kinematic (eddy) viscosity of the shallow-water ``pool`` [m²/s]."""
    cfl: float = field(default=0.4, metadata=_positive(0.7))
    """Courant number of the pools' steps: dt = cfl·Δx / (|u| + √(g h)) [-]; the explicit gravity
    step is stable up to 1/√2 in 2-D, hence at most 0.7."""
    drops: tuple[DropConfig, ...] = ()
    """Drops falling into the ``pool`` or ``wavepool``: ``[[water.drops]]`` tables with time_s,
    x_m, y_m, radius_m, height_m."""
    body: BodyConfig = field(default_factory=BodyConfig)
    """A body moving through the ``pool`` on a circular path, pushing the water."""
    wave_speed_m_s: float = field(default=0.0, metadata=_range(0.0, 100.0))
    """Wave speed c of the ``wavepool`` [m/s]; 0 means the shallow-water speed √(g·floor.depth_m)."""
    damping_per_s: float = field(default=0.5, metadata=_range(0.0, 100.0))
    """Damping γ of the ``wavepool`` (η_tt = c²∇²η − γη_t): energy decays as e^(−γt) [1/s]."""
    seed: int = field(default=0, metadata=_range(0, 2**63 - 1))
    """Seed of the ocean's random phases and amplitudes."""
    procedural_amplitude: float = field(default=0.01, metadata=_range(0.0, 1.0))
    """A of the ``procedural`` waves (GPU Gems ch. 2's VTXSIZE): η = 2Aℓ·r·Σ −f cos(…) [-]."""
    procedural_frequency: float = field(default=10.0, metadata=_positive(1.0e4))
    """W of the ``procedural`` waves (the chapter's WAVESIZE): phase W·x̂·ŷ/f in units of ℓ [-]."""
    procedural_factor: float = field(default=1.0, metadata=_positive(100.0))
    """f_0 of the ``procedural`` waves (the chapter's FACTOR): the first octave's weight; each
    further octave halves it [-]."""
    procedural_speed_rad_s: float = field(default=2.0, metadata=_range(-1.0e3, 1.0e3))
    """S of the ``procedural`` waves (the chapter's SPEED): phase rate [rad/s]."""
    procedural_octaves: int = field(default=4, metadata=_range(1, 16))
    """Number of octaves of the ``procedural`` waves [-]."""
    procedural_scale_m: float = field(default=0.0, metadata=_length())
    """ℓ, one model unit of the chapter's shader in metres [m]; 0 = half of ``extent_m``."""

    @property
    def walled(self) -> bool:
        """The stateful pools have walls."""
        return self.model in (WaterModel.POOL, WaterModel.WAVEPOOL)

    @property
    def periodic(self) -> bool:
        """A tileable patch (flat, heightfield, fft); the pools and the procedural waves are not."""
        return not self.walled and self.model is not WaterModel.PROCEDURAL

    @property
    def stateful(self) -> bool:
        """Frame k steps on from frame k−1 (the pools); the other models are functions of time."""
        return self.walled
