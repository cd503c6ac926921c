"""Outputs: EXR, PNG, NumPy/NetCDF, VTK meshes, run.json, and the 3-D preview.

``frame.save_frame`` runs the frame writers registered in ``frame.WRITERS`` (``images``,
``vtk_meshes``, ``arrays``, ``comparison``); ``run_json.write_run_json`` comes last; ``files``
holds the atomic-write, JSON and CSV helpers they share.
"""
