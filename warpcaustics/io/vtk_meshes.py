"""VTK files of a frame for ParaView and pyvista: the water surface, the floor map, the receivers.

(Not named ``vtk.py``: pyvista imports the ``vtk`` package.)
"""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np


def band_name(wavelength_nm: float) -> str:
    """Name of a per-band VTK array: ``irradiance_437.5nm``."""
    return f"irradiance_{wavelength_nm:g}nm"


def _save_mesh(mesh, path: Path) -> None:
    """pyvista picks the writer from the extension, so the temporary name keeps it."""
    tmp = path.with_name(f".{path.stem}.tmp-{os.getpid()}{path.suffix}")
    try:
        mesh.save(str(tmp))
        os.replace(tmp, path)
    finally:
        if tmp.exists():
            tmp.unlink()


def write_vtk(result, out_dir: Path, *, frame: int = 0) -> dict[str, Path]:
    """VTK files of one frame (readable by ParaView and pyvista), each written atomically:

    - ``surface_NNNN.vts``: the water surface's N×N vertices [m] with point data ``normal``;
    - ``floor_NNNN.vti``: the floor map as image cells over the patch at the floor's rest depth,
      cell data ``irradiance_<λ>nm`` [W m^-2 nm^-1] per band;
    - ``receivers_NNNN.vtp`` (photons, beams): the receiver meshes other than the floor, cell data
      ``irradiance_<λ>nm`` per band and ``receiver`` (1 = walls, 2 + i = ``receivers[i]``).
    """
    import warnings

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        import pyvista as pv

    paths = {}
    stem = f"{frame:04d}"
    pos = result.surface_positions.astype(np.float64)
    grid = pv.StructuredGrid(pos[..., 0].T, pos[..., 1].T, pos[..., 2].T)
    grid.point_data["normal"] = result.surface_normals.reshape(-1, 3)  # points run x fastest, as here
    paths["surface_vtk"] = out_dir / f"surface_{stem}.vts"
    _save_mesh(grid, paths["surface_vtk"])

    m = result.floor_irradiance.shape[-1]
    extent = result.map_extent_m
    cx, cy = result.map_center_m
    image = pv.ImageData(dimensions=(m + 1, m + 1, 1), spacing=(extent / m, extent / m, 1.0),
                         origin=(cx - extent / 2, cy - extent / 2, -result.scene.config.floor.depth_m))
    for wl, band in zip(result.wavelengths_nm, result.floor_irradiance):
        image.cell_data[band_name(wl)] = band.ravel()  # row index along +y: x varies fastest
    paths["floor_vtk"] = out_dir / f"floor_{stem}.vti"
    _save_mesh(image, paths["floor_vtk"])

    if result.receiver_mesh is not None:
        points, triangles = result.receiver_mesh
        faces = np.hstack([np.full((len(triangles), 1), 3), triangles]).ravel()
        poly = pv.PolyData(points, faces)
        irradiance = result.face_flux_w_nm / result.face_area_m2[:, None]
        for k, wl in enumerate(result.wavelengths_nm):
            poly.cell_data[band_name(wl)] = irradiance[:, k]
        poly.cell_data["receiver"] = result.face_receiver
        paths["receivers_vtk"] = out_dir / f"receivers_{stem}.vtp"
        _save_mesh(poly, paths["receivers_vtk"])
    return paths
