"""What a render returns: :class:`RenderResult`, a frame's maps and images as numpy arrays."""

from __future__ import annotations

import numbers
import os
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from warpcaustics.errors import ConfigError, WarpcausticsError
from warpcaustics.optics import spectra

if TYPE_CHECKING:
    from warpcaustics.scene import Scene


@dataclass
class RenderResult:
    """A rendered frame, as numpy arrays on the host."""

    scene: Scene
    time_s: float
    device: str
    wavelengths_nm: np.ndarray
    """(K,) bin centres [nm]."""
    bin_widths_nm: np.ndarray
    """(K,) bin widths [nm]."""
    floor_irradiance: np.ndarray
    """(K, M, M) spectral irradiance on the floor [W m^-2 nm^-1]; row index along +y, texel
    centres at ``(i + 0.5) L/M - L/2`` (with a floor-map window, :meth:`map_coordinates`)."""
    attenuation_per_m: np.ndarray
    """(K,) beam attenuation c(λ) = a + b used [1/m]."""
    ior: np.ndarray
    """(K,) refractive index n(λ) used."""
    sun_irradiance: np.ndarray
    """(K,) solar spectral irradiance on a plane perpendicular to the beam [W m^-2 nm^-1]."""
    transmitted_flux_w_nm: np.ndarray
    """(K,) flux that enters the water through the surface [W nm^-1], before any attenuation: sun
    (and sky) irradiance × the lit surface's area seen from the light × Fresnel transmittance. The
    same for every method (the flux-ratio methods count it per surface triangle, photons and beams
    per photon and beam, the random walk per walker)."""
    surface_positions: np.ndarray
    """(N, N, 3) water surface vertices [m]."""
    surface_normals: np.ndarray
    """(N, N, 3) unit surface normals."""
    delivered_flux_w_nm: np.ndarray | None = None
    """``fluxratio`` (single scattering): (K,) flux the surface triangles send to the floor after
    attenuation along their refracted paths [W nm^-1] — the floor map's flux plus what lands outside
    it (beyond a pool's walls or a map window). Before 0.2 this was ``transmitted_flux_w_nm``."""
    bins: spectra.SpectralBins | None = None
    """The spectral bins (edges, and the listed wavelengths when point-sampled)."""
    fold_fraction: float = 0.0
    """Fraction of surface vertices where choppy displacement folds the surface (Jacobian ≤ 0)."""
    timings_s: dict[str, float] = field(default_factory=dict)
    """Wall time of each stage [s] (device synchronised)."""
    face_flux_w_nm: np.ndarray | None = None
    """``photons``, ``beams``: (F, K) flux on each receiver face that is not floor [W nm^-1], faces
    ordered walls, then ``receivers[i]`` (see :attr:`face_receiver`)."""
    face_receiver: np.ndarray | None = None
    """``photons``, ``beams``: (F,) receiver id of each of those faces (1 = walls, 2 + i =
    ``receivers[i]``)."""
    face_area_m2: np.ndarray | None = None
    """``photons``, ``beams``: (F,) area of each of those faces [m²]."""
    face_centres_m: np.ndarray | None = None
    """``photons``, ``beams``: (F, 3) centroid of each of those faces [m]."""
    floor_texel_area_m2: np.ndarray | None = None
    """``photons``, ``beams``: (M, M) true area of the floor over each texel [m²] (None: flat, (L/M)²)."""
    receiver_mesh: tuple[np.ndarray, np.ndarray] | None = None
    """``photons``, ``beams``: (points (V, 3) [m], triangles (F, 3)) of the receivers other than the
    floor, the faces in the order of :attr:`face_flux_w_nm`."""
    photon_stats: dict[str, int] | None = None
    """``photons``: photons emitted, carrying flux, and landed on a receiver, added up over the
    frame's light passes (one per direction of the sun's disk and of the sky)."""
    beam_stats: dict[str, int] | None = None
    """``beams``: beams built, carrying flux, dropped, and tile-list entries, added up over the
    frame's light passes."""
    method: str = "fluxratio"
    """The caustics method that made :attr:`floor_irradiance` (``beams`` for ``both``)."""
    comparison: RenderResult | None = None
    """``both``: the photon method's result of the same frame (this result is the beams');
    ``sunmap``, ``eikonal``, ``wave3d``: the flux-ratio map of the same frame. Saved beside it with
    the difference of the floor maps."""
    sunmap_brightness: np.ndarray | None = None
    """``sunmap``: (M, M) grey sun-map brightness 0…1 before scaling to the flux-ratio mean."""
    eikonal_stats: dict[str, int] | None = None
    """``eikonal``: layers of the grid and Jacobi passes of the relaxation."""
    wave3d_stats: dict[str, int] | None = None
    """``wave3d``: layers of the grid, steps, averaged steps and node updates."""
    multiple_scattering_stats: dict | None = None
    """``optics.scattering = "multiple"``: photons walked and, per band, where their flux went
    (transmitted, floor, escaped, absorbed, unscattered, truncated) [W nm⁻¹]."""
    sky_floor_irradiance: np.ndarray | None = None
    """With a sky (``sky.model``): (K, M, M) the sky's part of :attr:`floor_irradiance`
    [W m⁻² nm⁻¹]; the direct sun's is the rest."""
    sky_floor_irradiance_even: np.ndarray | None = None
    """``sky.sampling = "halves"``: (K, M, M) the part of :attr:`sky_floor_irradiance` from the
    first half of the sky's directions (the even-numbered; the rest is the second half's): two
    independent estimates of the sky's continuum, for statistics without the directions' own
    caustic noise (:func:`warpcaustics.batch.stats.continuous_sky_cv`)."""
    coarse_floor_irradiance: np.ndarray | None = None
    """A window of a periodic sea under the small-angle transfer or a sky in cones: (K, Mc, Mc) the
    whole patch's light on the coarse texels the transfer and the cones take its large scales from
    [W m⁻² nm⁻¹], the map's counterpart over the patch: the variance at scales above the window
    (:func:`warpcaustics.batch.stats.frame_statistics`'s ``patch_windows``)."""
    coarse_sky_floor_irradiance: np.ndarray | None = None
    """With :attr:`coarse_floor_irradiance` and a sky: the sky's part of it."""
    camera_radiance: np.ndarray | None = None
    """(K, H, W) spectral radiance reaching the camera [W m^-2 sr^-1 nm^-1], image row 0 at the top."""
    camera_gbuffer: dict[str, np.ndarray] | None = None
    """Per camera pixel: ``position`` (H, W, 3) [m], ``normal`` (H, W, 3), ``depth`` (H, W) [m] along
    the ray (inf: no receiver), ``receiver`` (H, W) id (−1: none); above the water the ray is the
    refracted one (or the camera's, where it misses the water) and ``face`` (H, W) is the receivers'
    face it meets (the floor's first, then the others in ``face_area_m2``'s order; −1: none)."""

    def water_iops(self) -> dict:
        """The water's absorption ``a``, scattering ``b`` and beam attenuation ``c`` [1/m] used by
        this render, as ``colour.SpectralDistribution``s on its wavelengths."""
        optics = spectra.water_optics(self.scene.config.optics, self.bins)
        return optics.distributions(self.bins)

    def receiver_irradiance(self, receiver: int) -> np.ndarray:
        """(F_r, K) irradiance on the faces of receiver id ``receiver`` [W m^-2 nm^-1]."""
        if self.face_flux_w_nm is None:
            raise ConfigError(f"receiver irradiance needs caustics.method = 'photons' or 'beams' (this "
                              f"render's is {self.method!r})")
        ids = sorted(int(i) for i in np.unique(self.face_receiver))
        if isinstance(receiver, (bool, np.bool_)) or not isinstance(receiver, numbers.Integral) \
                or int(receiver) not in ids:
            from warpcaustics.config.fields import _describe

            names = ", ".join(f"{i} ({'walls' if i == 1 else f'receivers[{i - 2}]'})" for i in ids) or "none"
            raise WarpcausticsError(f"receiver = {_describe(receiver)} is not a receiver id of this render; "
                                    f"its ids: {names}")
        sel = self.face_receiver == int(receiver)
        return self.face_flux_w_nm[sel] / self.face_area_m2[sel, None]

    @property
    def extent_m(self) -> float:
        return self.scene.config.water.extent_m

    @property
    def map_extent_m(self) -> float:
        """Side of the floor map [m]: the water extent, or ``caustics.map_extent_m``'s window."""
        return self.scene.config.map_window[0]

    @property
    def map_center_m(self) -> tuple[float, float]:
        """Centre of the floor map [m]."""
        return self.scene.config.map_window[1]

    @property
    def map_periodic(self) -> bool:
        """Whether the floor map tiles (the whole patch of a periodic sea, or a window as wide)."""
        c = self.scene.config
        side = c.caustics.map_extent_m
        return c.water.periodic and (not side or side >= c.water.extent_m)

    def map_coordinates(self) -> tuple[np.ndarray, np.ndarray]:
        """(x, y) [m] of the texel centres of the floor map (row index along +y)."""
        m = self.floor_irradiance.shape[-1]
        side = self.map_extent_m
        offsets = (np.arange(m) + 0.5) * side / m - 0.5 * side
        cx, cy = self.map_center_m
        return cx + offsets, cy + offsets

    @property
    def texel_area_m2(self) -> float:
        return (self.map_extent_m / self.floor_irradiance.shape[-1]) ** 2

    @property
    def floor_flux_w_nm(self) -> np.ndarray:
        """(K,) total flux on the floor [W nm^-1], summed in float64 over each texel's true floor
        area (a relief's area exceeds the texel's horizontal area)."""
        if self.floor_texel_area_m2 is not None:
            return np.einsum("kij,ij->k", self.floor_irradiance.astype(np.float64), self.floor_texel_area_m2)
        return self.floor_irradiance.sum(axis=(1, 2), dtype=np.float64) * self.texel_area_m2

    def save(self, out_dir: str | Path, *, frame: int = 0) -> dict[str, Path]:
        """Write ``frame_NNNN.exr``, ``frame_NNNN.png`` and then ``run.json`` into out_dir.

        Each file is written to a temporary name and renamed; run.json comes last.
        """
        from warpcaustics.io.frame import save_frame
        from warpcaustics.io.run_json import frame_entry, write_run_json

        if isinstance(frame, bool) or not isinstance(frame, numbers.Integral) or frame < 0:
            raise WarpcausticsError(f"frame = {frame!r} must be a whole number from 0 (the files' "
                                    "frame_NNNN names)")
        if not isinstance(out_dir, (str, os.PathLike)) or isinstance(out_dir, bytes) or "\0" in str(out_dir) \
                or out_dir == "":
            raise WarpcausticsError(f"out_dir = {out_dir!r:.60} must be a folder's path (a str or a Path)")
        frame = int(frame)
        try:
            paths = save_frame(self, Path(out_dir), frame=frame)
            # run.json names this frame's own files (frame_0005.*), not frame 0's
            paths["json"] = write_run_json(Path(out_dir), [self], frames=[frame_entry(frame, self)])
        except OSError as exc:
            raise WarpcausticsError(f"cannot save into {str(out_dir)!r}: {exc.strerror or exc}; give a "
                                    "folder that can be made and written") from None
        return paths
