"""Caustic methods: one module per ``caustics.method`` (flux ratio, photons, beams, sun map, eikonal,
wave3d) and the multiple-scattering random walk."""
