"""Float64 numpy references, written independently of the kernels with array operations (no Python
loops over triangles, photons, texels or pixels): the cross-checks of ``tests/`` and the baselines
of ``benchmarks/``.

- :mod:`~warpcaustics.reference.floor`: refraction, the crests' shading and the flux-ratio floor map
  (``kernels/optics/refract.py``, ``kernels/caustics/fluxratio.py``);
- :mod:`~warpcaustics.reference.photons`: photon splatting with the exact or Shah's Newton
  intersection (``kernels/caustics/photons.py``);
- :mod:`~warpcaustics.reference.beams`: the beam rasteriser's surface gather and scan-plane shafts
  (``kernels/caustics/beams/``);
- :mod:`~warpcaustics.reference.view`: a radiance sensor's sky traced back through the height field
  (``kernels/optics/view.py``).
"""

from __future__ import annotations

import numpy as np

from warpcaustics.reference.floor import (
    floor_caustics,
    fresnel_transmittance,
    march_visibility,
    refract,
    refract_to_floor,
    subtriangle_centroids,
    sun_visibility,
    sweep_visibility,
    triangles,
)

__all__ = ["fresnel_transmittance", "floor_caustics", "march_visibility", "refract", "refract_to_floor",
           "relative_l1", "subtriangle_centroids", "sun_visibility", "sweep_visibility", "triangles"]


def relative_l1(reference: np.ndarray, other: np.ndarray) -> float:
    """Σ|other − reference| / Σ|reference| over the whole map."""
    reference = np.asarray(reference, np.float64)
    return float(np.abs(np.asarray(other, np.float64) - reference).sum() / np.abs(reference).sum())
