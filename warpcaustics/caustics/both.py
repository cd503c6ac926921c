"""``caustics.method = "both"``: beams and photons on the same receivers and camera, the photons'
result saved beside the beams' as its comparison."""

from __future__ import annotations

from warpcaustics.caustics.beams import BeamCaustics, BeamStage
from warpcaustics.caustics.photons import PhotonCaustics, PhotonStage
from warpcaustics.caustics.receiver_stage import CausticsSetup, PassCaustics, ReceiverStage


class BothStage(ReceiverStage):
    """Beams first (the result), photons second (the comparison)."""

    name = "both"

    def make_caustics(self, setup: CausticsSetup) -> list[PassCaustics]:
        return [BeamCaustics(setup), PhotonCaustics(setup)]

    @classmethod
    def caustics_bytes(cls, scene, n: int, k: int, groups: int, faces: int) -> int:
        return (BeamStage.caustics_bytes(scene, n, k, groups, faces)
                + PhotonStage.caustics_bytes(scene, n, k, groups, faces))
