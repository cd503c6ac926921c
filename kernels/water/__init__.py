"""Device code of the water models: FFT ocean, shallow-water and wave-equation pools, procedural waves,
height fields."""
