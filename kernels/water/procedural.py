"""Procedural octave waves: the wave function of GPU Gems ch. 2 and its analytic gradient.

Guardado & Sánchez-Crespo, "Rendering Water Caustics", GPU Gems (2004), ch. 2: the shader's
``wave(x, y, t)`` and ``gradwave(x, y, t)``. With r = √(x² + y²), octave o = 0…O−1 and
f_o = f_0 / 2^o, in the chapter's unit coordinates (x̂ = x/ℓ here)

    w(x̂, ŷ, t) = 2 A r Σ_o −f_o cos(φ_o),   φ_o = S t + W x̂ ŷ / f_o,
    ∂w/∂x̂ = 2 A Σ_o [ r W ŷ sin(φ_o) − f_o cos(φ_o) x̂ / r ]   (and x̂ ↔ ŷ for ∂w/∂ŷ).

The chapter works in the demo's model units; ``scale_m`` = ℓ maps them to metres: η = ℓ·w(x/ℓ,
y/ℓ, t), so slopes ∂η/∂x = ∂w/∂x̂ are the chapter's. The function is an aesthetic one (the chapter
says so): it does not tile, its amplitude grows with r, and it has a cone point at the origin,
where the gradient is taken as the average of its limits (the r-term dropped).
"""

import warp as wp

from warpcaustics.kernels.geometry import cell_centre, normal_from_slopes

wp.set_module_options({"enable_backward": False})


@wp.struct
class OctaveWaves:
    amplitude: float
    """A, the chapter's VTXSIZE [-]."""
    frequency: float
    """W, the chapter's WAVESIZE, in unit coordinates [-]."""
    factor: float
    """f_0, the chapter's FACTOR: the first octave's amplitude weight [-]."""
    speed_rad_s: float
    """S, the chapter's SPEED [rad/s]."""
    octaves: int
    """O, the number of octaves (each halves f) [-]."""
    scale_m: float
    """ℓ, the length [m] of one of the chapter's model units."""


@wp.func
def octave_wave(waves: OctaveWaves, x: float, y: float, time_s: float) -> wp.vec3:
    """(η [m], ∂η/∂x, ∂η/∂y) at (x, y): ℓ times the chapter's ``wave`` and its ``gradwave`` at
    (x/ℓ, y/ℓ), in one pass over the octaves (one sine and one cosine each)."""
    u = x / waves.scale_m
    v = y / waves.scale_m
    r = wp.sqrt(u * u + v * v)
    ur = float(0.0)
    vr = float(0.0)
    if r > 0.0:
        ur = u / r
        vr = v / r
    f = waves.factor
    z = float(0.0)
    gx = float(0.0)
    gy = float(0.0)
    for _o in range(waves.octaves):
        phase = waves.speed_rad_s * time_s + u * v * waves.frequency / f
        s = wp.sin(phase)
        c = wp.cos(phase)
        z -= f * c
        gx += r * s * v * waves.frequency - f * c * ur
        gy += r * s * u * waves.frequency - f * c * vr
        f = 0.5 * f
    a2 = 2.0 * waves.amplitude
    return wp.vec3(waves.scale_m * a2 * r * z, a2 * gx, a2 * gy)


@wp.kernel
def octave_surface(
    waves: OctaveWaves,
    time_s: float,
    extent_m: float,
    positions: wp.array2d[wp.vec3],
    normals: wp.array2d[wp.vec3],
):
    """Vertices at cell centres with z = η; normals from the analytic gradient."""
    iy, ix = wp.tid()
    xy = cell_centre(ix, iy, positions.shape[0], extent_m)
    w = octave_wave(waves, xy[0], xy[1], time_s)
    positions[iy, ix] = wp.vec3(xy[0], xy[1], w[0])
    normals[iy, ix] = normal_from_slopes(w[1], w[2])
