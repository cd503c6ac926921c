"""Phase functions of in-water scattering, evaluated on the device (for the volume caustics)."""

import warp as wp

wp.set_module_options({"enable_backward": False})

INV_4PI = 0.07957747154594767


@wp.func
def henyey_greenstein(cos_theta: float, g: float) -> float:
    """Henyey–Greenstein phase function [1/sr], normalised over the sphere; mean cosine g."""
    denom = 1.0 + g * g - 2.0 * g * cos_theta
    return INV_4PI * (1.0 - g * g) / (denom * wp.sqrt(denom))


@wp.func
def tabulated_phase(angles_rad: wp.array[wp.float32], log_phase: wp.array[wp.float32],
                    cone_phase: float, cos_theta: float) -> float:
    """Phase function [1/sr] from a table: ln p linear in θ between nodes; ``cone_phase`` inside
    the forward cone below the first node.

    Taking cos θ in float32 limits θ to ~0.02° near the forward direction (cos θ = 1 − θ²/2).
    """
    theta = wp.acos(wp.clamp(cos_theta, -1.0, 1.0))
    count = angles_rad.shape[0]
    if theta < angles_rad[0]:
        return cone_phase
    for i in range(1, count):
        if theta <= angles_rad[i]:
            t = (theta - angles_rad[i - 1]) / (angles_rad[i] - angles_rad[i - 1])
            return wp.exp(log_phase[i - 1] + t * (log_phase[i] - log_phase[i - 1]))
    return wp.exp(log_phase[count - 1])


@wp.func
def phase_value(kind: int, g: float, angles_rad: wp.array[wp.float32], log_phase: wp.array[wp.float32],
                cone_phase: float, cos_theta: float) -> float:
    """p(cos θ) [1/sr] of the configured phase function: kind 0 = Henyey–Greenstein(g), 1 = the table."""
    if kind == 0:
        return henyey_greenstein(cos_theta, g)
    return tabulated_phase(angles_rad, log_phase, cone_phase, cos_theta)


@wp.kernel
def evaluate_phase(cos_theta: wp.array[wp.float32], kind: int, g: float,
                   angles_rad: wp.array[wp.float32], log_phase: wp.array[wp.float32], cone_phase: float,
                   out: wp.array[wp.float32]):
    """out[i] = p(cos θ_i): kind 0 = Henyey–Greenstein(g), 1 = the table."""
    i = wp.tid()
    out[i] = phase_value(kind, g, angles_rad, log_phase, cone_phase, cos_theta[i])
