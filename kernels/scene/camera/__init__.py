"""The under-water pinhole camera: G-buffer by ray casting, photon splats, light shafts, shading.

- :mod:`.pinhole`: the camera, its pixel rays and projection, the G-buffer, the final shading;
- :mod:`.splats`: photon splats into the camera's caustic map (tents and Gaussians);
- :mod:`.shafts`: light shafts drawn into a pixel pyramid, collapsed and blurred.

What host code launches is re-exported here (``camera_kernels.gbuffer``).
"""

from warpcaustics.kernels.scene.camera.pinhole import PinholeCamera, gbuffer, shade
from warpcaustics.kernels.scene.camera.shafts import SHAFT_LEVELS, blur3, collapse_pyramid, shaft_lines
from warpcaustics.kernels.scene.camera.splats import splat_photons

__all__ = [
    "SHAFT_LEVELS",
    "PinholeCamera",
    "blur3",
    "collapse_pyramid",
    "gbuffer",
    "shade",
    "shaft_lines",
    "splat_photons",
]
