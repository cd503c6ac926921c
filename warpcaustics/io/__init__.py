"""Outputs: EXR, PNG, NumPy/NetCDF, VTK meshes, run.json, and the 3-D preview."""
