"""``warpcaustics preview``: an off-screen 3-D view (pyvista) of a rendered frame.

The floor (and, with photons or beams, every receiver) is coloured by its band-integrated irradiance
[W m^-2] on a logarithmic scale; the water surface is drawn translucent above it. Meant for
checking a scene's set-up at a glance, not as a rendering: the pictures of record are the EXRs.
"""

from __future__ import annotations

import os
import warnings
from contextlib import contextmanager
from pathlib import Path

import numpy as np

from warpcaustics.errors import WarpcausticsError


@contextmanager
def vtk_errors_only():
    """VTK's own log on stderr cut to its errors: an off-screen window without an X server logs a
    warning ("bad X server connection") from C++ every time, though it renders; a failure still
    reaches us as an exception, which we report in one line."""
    from vtkmodules.vtkCommonCore import vtkLogger

    previous = vtkLogger.GetCurrentVerbosityCutoff()  # stderr's level where it is the only log (default)
    vtkLogger.SetStderrVerbosity(vtkLogger.VERBOSITY_ERROR)
    try:
        yield
    finally:
        vtkLogger.SetStderrVerbosity(previous)


def preview_png(result, path: Path, *, width: int = 960, height: int = 640) -> Path:
    """Draw ``result`` (a RenderResult) into a PNG at ``path`` (written atomically)."""
    with vtk_errors_only():
        return _draw(result, path, width, height)


def _draw(result, path: Path, width: int, height: int) -> Path:
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        import pyvista as pv

    widths = result.bin_widths_nm
    extent = result.map_extent_m
    cx, cy = result.map_center_m
    depth = result.scene.config.floor.depth_m
    m = result.floor_irradiance.shape[-1]
    floor = pv.ImageData(
        dimensions=(m + 1, m + 1, 1),
        spacing=(extent / m, extent / m, 1.0),
        origin=(cx - extent / 2, cy - extent / 2, -depth),
    )
    floor.cell_data["irradiance"] = np.einsum("kij,k->ij", result.floor_irradiance, widths).ravel()
    pos = result.surface_positions.astype(np.float64)
    surface = pv.StructuredGrid(pos[..., 0].T, pos[..., 1].T, pos[..., 2].T)

    positive = floor.cell_data["irradiance"][floor.cell_data["irradiance"] > 0]
    lo, hi = np.percentile(positive, [1, 99.5]) if positive.size else (1e-3, 1.0)
    plotter = pv.Plotter(off_screen=True, window_size=(width, height))
    plotter.set_background("white")
    clim = (lo, max(hi, lo * 10))
    bar = {"title": "irradiance [W m^-2]", "color": "black"}
    plotter.add_mesh(
        floor, scalars="irradiance", cmap="magma", log_scale=True, clim=clim, scalar_bar_args=bar
    )
    if result.receiver_mesh is not None:
        points, triangles = result.receiver_mesh
        mesh = pv.PolyData(points, np.hstack([np.full((len(triangles), 1), 3), triangles]).ravel())
        irradiance = result.face_flux_w_nm / result.face_area_m2[:, None]
        mesh.cell_data["irradiance"] = np.maximum(irradiance @ widths, lo * 1e-3)
        mesh.cell_data["receiver"] = result.face_receiver
        walls = mesh.threshold(value=(0.5, 1.5), scalars="receiver")
        objects = mesh.threshold(value=1.5, scalars="receiver")
        style = {
            "scalars": "irradiance",
            "cmap": "magma",
            "log_scale": True,
            "clim": clim,
            "show_scalar_bar": False,
        }
        if objects.n_cells:
            plotter.add_mesh(objects, **style)
        if walls.n_cells:  # translucent, so that the pool's inside shows through them
            plotter.add_mesh(walls, opacity=0.25, **style)
    plotter.add_mesh(surface, color="lightblue", opacity=0.3, smooth_shading=True)
    plotter.camera_position = [  # looking at the floor map (a window's centre, if any)
        (cx + 0.9 * extent, cy - 1.1 * extent, 1.1 * extent),
        (cx, cy, -0.6 * depth),
        (0, 0, 1),
    ]
    tmp = path.with_name(f".{path.stem}.tmp-{os.getpid()}.png")  # VTK knows its formats by lower case
    try:
        plotter.screenshot(str(tmp))
    except Exception as exc:  # VTK without an off-screen context reports in many ways
        raise WarpcausticsError(
            f"preview: pyvista could not render off screen ({type(exc).__name__}: "
            f"{str(exc).splitlines()[0] if str(exc) else ''}); the EXR and VTK outputs "
            "do not need it"
        ) from None
    else:
        try:
            os.replace(tmp, path)
        except OSError as exc:
            raise WarpcausticsError(f"preview: cannot write {str(path)!r}: {exc.strerror or exc}") from None
    finally:
        plotter.close()
        if tmp.exists():
            tmp.unlink()
    return path
