"""Optics: water types and spectra, refraction and Fresnel, phase functions, the sun's position, colour."""
