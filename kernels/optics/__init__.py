"""Device code of the optics: refraction with Fresnel transmittance, phase functions."""
