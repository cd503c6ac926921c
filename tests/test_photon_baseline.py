"""The numpy baseline of the photon benchmark (benchmarks/photons.py) does the Warp stage's work."""

from __future__ import annotations

import pytest


@pytest.mark.parametrize("intersection", ["exact", "newton"])
def test_numpy_photons_match_warp(intersection):
    """The float64 numpy photon splatting and the Warp photon stage give the same floor map."""
    from warpcaustics.reference import relative_l1
    from warpcaustics.reference.photons import numpy_photons

    from benchmarks.photons import PhotonCase

    case = PhotonCase(32, 2, 32, intersection, "cpu")
    warp_map = case.run_warp()
    numpy_map = numpy_photons(**case.numpy_inputs())
    # float32 (Warp) vs float64 (numpy) rounding alone gives ~5e-8. A photon within ~1e-6 m of a
    # texel edge could land on the other side and cost 2/4096 ≈ 5e-4, but on this surface the
    # nearest lands 5e-5 m from an edge. A baseline that skips work is far off: index 1.34 for
    # 1.333 gives 4e-2, attenuation ×1.1 gives 3e-2, one photon per quad instead of 2×2 gives 0.3.
    assert relative_l1(numpy_map, warp_map) < 1e-4
