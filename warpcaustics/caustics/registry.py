"""Every caustic method by its ``caustics.method`` name: adding one is a module with its
:class:`~warpcaustics.caustics.stage.CausticStage` subclass, its kernels, its tests and a line here."""

from __future__ import annotations

from warpcaustics.caustics.beams import BeamStage
from warpcaustics.caustics.both import BothStage
from warpcaustics.caustics.eikonal import EikonalStage
from warpcaustics.caustics.fluxratio import FluxRatioStage
from warpcaustics.caustics.photons import PhotonStage
from warpcaustics.caustics.stage import CausticStage
from warpcaustics.caustics.sunmap import SunMapStage
from warpcaustics.caustics.wave3d import Wave3DStage
from warpcaustics.config import CausticsMethod

METHODS: dict[CausticsMethod, type[CausticStage]] = {
    CausticsMethod.FLUXRATIO: FluxRatioStage,
    CausticsMethod.PHOTONS: PhotonStage,
    CausticsMethod.BEAMS: BeamStage,
    CausticsMethod.BOTH: BothStage,
    CausticsMethod.SUNMAP: SunMapStage,
    CausticsMethod.EIKONAL: EikonalStage,
    CausticsMethod.WAVE3D: Wave3DStage,
}


def method_stage(method: CausticsMethod) -> type[CausticStage]:
    """The stage class of ``caustics.method``."""
    return METHODS[method]
