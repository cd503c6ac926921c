"""Receivers of caustic light: the floor relief, pool walls and meshes, all in one Warp BVH.

Faces are stored floor first, then walls, then each mesh in config order; ``face_receiver`` maps
a face to its receiver id (0 = floor, 1 = walls, 2 + i = ``receivers[i]``). The BVH is built on
the real vertex positions (``wp.Mesh``), so ray queries are exact.
"""

from __future__ import annotations

import functools
import logging
import math
import shutil
import tempfile
import warnings
from contextlib import contextmanager
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import warp as wp

from warpcaustics.config import Config, FloorConfig, FloorShape, ReceiverConfig
from warpcaustics.config.fields import MAX_LENGTH_M
from warpcaustics.errors import ConfigError
from warpcaustics.io.files import input_file, load_npy
from warpcaustics.optics.spectra import SpectralBins

FLOOR_ID = 0
WALLS_ID = 1
FIRST_MESH_ID = 2

PRIMITIVES = ("sphere", "cube", "cylinder", "cone")
"""Built-in meshes (pyvista's primitives): unit size, centred at the origin, axis along z."""

WALL_ALBEDO = (0.8,)
"""Grey albedo of a walled pool's walls [-]."""

WALL_CELLS = 32
"""Wall quads per side along the wall (and 8 up it)."""

WALL_FACES = 4 * 2 * WALL_CELLS * 8
"""Triangles of the four walls."""


def floor_relief_height(
    floor: FloorConfig, relief: np.ndarray | None, extent_m: float, x: np.ndarray, y: np.ndarray
) -> np.ndarray:
    """Floor height z(x, y) [m] (float64): -depth_m plus the relief of ``floor.shape``."""
    x = np.asarray(x, np.float64)
    y = np.asarray(y, np.float64)
    z = np.full(np.broadcast(x, y).shape, -floor.depth_m)
    if floor.shape is FloorShape.SLOPE:
        az = math.radians(floor.slope_azimuth_deg)
        z -= math.tan(math.radians(floor.slope_deg)) * (x * math.cos(az) + y * math.sin(az))
    elif floor.shape is FloorShape.RIPPLES:
        az = math.radians(floor.ripple_direction_deg)
        phase = 2.0 * math.pi * (x * math.cos(az) + y * math.sin(az)) / floor.ripple_wavelength_m
        z += floor.ripple_amplitude_m * np.sin(phase)
    elif floor.shape is FloorShape.FILE:
        z += periodic_bilinear(relief, extent_m, x, y)
    return z


def periodic_bilinear(h: np.ndarray, extent_m: float, x: np.ndarray, y: np.ndarray) -> np.ndarray:
    """Bilinear interpolation of cell-centre samples h[iy, ix] over the patch, wrapping at its edges."""
    n = h.shape[0]
    u = (x + 0.5 * extent_m) * n / extent_m - 0.5
    v = (y + 0.5 * extent_m) * n / extent_m - 0.5
    i0 = np.floor(u).astype(np.int64)
    j0 = np.floor(v).astype(np.int64)
    tu, tv = u - i0, v - j0
    i0, j0 = i0 % n, j0 % n
    i1, j1 = (i0 + 1) % n, (j0 + 1) % n
    return (1 - tv) * ((1 - tu) * h[j0, i0] + tu * h[j0, i1]) + tv * ((1 - tu) * h[j1, i0] + tu * h[j1, i1])


def load_floor_relief(name: str, base_dir: Path) -> np.ndarray:
    """Read ``floor.file``: a square 2-D float array of relief [m]; one-line errors otherwise."""
    path = input_file("floor.file", name, base_dir, "a .npy file of floor relief")
    relief = load_npy("floor.file", path, "relief")
    if relief.ndim != 2 or relief.shape[0] != relief.shape[1] or relief.shape[0] < 2:
        raise ConfigError(
            f"floor.file = {str(path)!r} has shape {relief.shape}; expected a square 2-D "
            "array of at least 2×2 heights"
        )
    if not np.issubdtype(relief.dtype, np.floating) or not np.all(np.isfinite(relief)):
        raise ConfigError(f"floor.file = {str(path)!r} must hold finite float heights [m]")
    relief = relief.astype(np.float64)
    if np.abs(relief).max() > MAX_LENGTH_M:
        raise ConfigError(f"floor.file = {str(path)!r} holds relief of {np.abs(relief).max():.3g} m; relief "
                          f"must lie within ±{MAX_LENGTH_M:g} m")
    return relief


@dataclass(frozen=True)
class TriangleMesh:
    """Vertices (V, 3) [m] and triangles (F, 3) of one receiver, in world space."""

    points: np.ndarray
    triangles: np.ndarray


@contextmanager
def quiet_vtk():
    """Keep a reader's own log off the terminal (pyvista routes VTK's errors to Python's logging):
    the one-line error that follows says what went wrong."""
    previous = logging.root.manager.disable
    logging.disable(logging.CRITICAL)
    try:
        yield
    finally:
        logging.disable(previous)


def load_receiver_mesh(receiver: ReceiverConfig, base_dir: Path, key: str) -> TriangleMesh:
    """Read (or build) a receiver's mesh with pyvista and apply its scale, rotation, translation."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        import pyvista as pv

        if receiver.mesh in PRIMITIVES:
            poly = _primitive(receiver.mesh)
        else:
            path = input_file(f"{key}.mesh", receiver.mesh, base_dir,
                              f"a mesh file or a built-in mesh ({', '.join(PRIMITIVES)})")
            problem = _binary_stl_problem(path)
            try:
                if problem is None:
                    with quiet_vtk(), _without_bom(path) as readable:
                        poly = pv.read(str(readable))
            except Exception as exc:  # pyvista raises many kinds for unreadable files
                raise ConfigError(
                    f"{key}.mesh = {receiver.mesh!r} cannot be read by pyvista: "
                    f"{str(exc).splitlines()[0] if str(exc) else type(exc).__name__}"
                ) from None
            problem = problem or _mesh_problem(poly, pv)  # before clean(), which follows the indices
            if problem is not None:
                raise ConfigError(f"{key}.mesh = {receiver.mesh!r} {problem}; repair or re-export it")
        poly = poly.extract_surface().triangulate().clean()
    if poly.n_cells == 0:
        raise ConfigError(f"{key}.mesh = {receiver.mesh!r} has no triangles: an empty mesh, or a file "
                          f"pyvista could not make sense of (check that it is a mesh in the format its "
                          f"suffix names)")
    points = np.asarray(poly.points, np.float64)
    triangles = np.asarray(poly.faces, np.int64).reshape(-1, 4)[:, 1:]
    scale = np.broadcast_to(np.asarray(receiver.scale, np.float64), (3,))
    rx, ry, rz = (math.radians(a) for a in receiver.rotate_deg)
    rotation = _rot_z(rz) @ _rot_y(ry) @ _rot_x(rx)
    points = (points * scale) @ rotation.T + np.asarray(receiver.translate_m)
    if points.size and np.abs(points).max() > MAX_LENGTH_M:  # in the scene, after scale and placing
        raise ConfigError(f"{key}.mesh = {receiver.mesh!r} reaches {np.abs(points).max():.3g} m from the "
                          f"origin once scaled and placed; the scene lies within ±{MAX_LENGTH_M:g} m (check "
                          f"the file's units against {key}.scale)")
    return TriangleMesh(points, triangles)


BOM_TEXT_FORMATS = (".stl", ".obj", ".ply", ".vtk", ".off")
"""Mesh formats whose VTK readers choke on a UTF-8 byte-order mark (the XML formats read it, and a
multi-file one must stay beside its parts)."""


@contextmanager
def _without_bom(path: Path):
    """The file, or a copy of it without the UTF-8 byte-order mark some editors write at the start of
    text files: VTK's STL reader reads none of such a file, its OBJ reader loses the first line."""
    with open(path, "rb") as fh:
        start = fh.read(4096)
        binary_stl = path.suffix.lower() == ".stl" and not _ascii_stl(start)  # its header is any 80 bytes
        if not start.startswith(b"\xef\xbb\xbf") or binary_stl or path.suffix.lower() not in BOM_TEXT_FORMATS:
            yield path
            return
        fh.seek(3)
        with tempfile.TemporaryDirectory() as folder:
            copy = Path(folder) / path.name
            with open(copy, "wb") as out:
                shutil.copyfileobj(fh, out)
            yield copy


def _ascii_stl(start: bytes) -> bool:
    """Whether a file's first bytes are an ASCII STL's (``solid``, then a facet), a BOM aside."""
    start = start.lower()
    return start.removeprefix(b"\xef\xbb\xbf").lstrip().startswith(b"solid") and b"facet" in start


def _binary_stl_problem(path: Path) -> str | None:
    """Why a binary STL is not whole (its size against the triangles its header declares), or None:
    VTK reads what there is of a truncated one without a word."""
    if path.suffix.lower() != ".stl":
        return None
    with open(path, "rb") as fh:
        head = fh.read(84)
        start = head + fh.read(4096)
    if _ascii_stl(start) or len(head) < 84:
        return None  # ASCII, or too short to say: the reader reports it
    declared = int.from_bytes(head[80:84], "little")
    size = path.stat().st_size
    if size < 84 + 50 * declared:
        return (f"is not a whole binary STL (cut short, or not an STL at all): its header declares "
                f"{declared} triangles, its {size} bytes hold {(size - 84) // 50}")
    return None


def _mesh_problem(data, pv) -> str | None:
    """What makes a mesh unusable before any filter touches it: faces that name vertices it does not
    hold (VTK's filters then read past the end), vertices that are not finite."""
    n = data.n_points if hasattr(data, "n_points") else 0
    if isinstance(data, pv.PolyData):
        cells = [pv.convert_array(getattr(data, kind)().GetConnectivityArray())
                 for kind in ("GetPolys", "GetStrips", "GetLines", "GetVerts")]
    elif isinstance(data, pv.UnstructuredGrid):
        cells = [np.asarray(data.cell_connectivity)]
    else:
        cells = []
    for index in cells:
        outside = index[(index < 0) | (index >= n)] if index.size else index
        if outside.size:
            return (f"has faces that refer to vertex {int(outside[0]) + 1}, but it holds {n} (truncated or "
                    "corrupt)")
    points = np.asarray(data.points, np.float64) if n else np.zeros((0, 3))
    if not np.all(np.isfinite(points)):
        return "has vertices that are not finite numbers"
    return None


@functools.cache
def _primitive(name: str):
    import pyvista as pv

    if name == "sphere":
        return pv.Sphere(radius=0.5, theta_resolution=64, phi_resolution=64)
    if name == "cube":
        return pv.Cube().triangulate().subdivide(3, subfilter="linear")
    if name == "cylinder":
        return pv.Cylinder(radius=0.5, height=1.0, direction=(0.0, 0.0, 1.0), resolution=64, capping=True)
    return pv.Cone(radius=0.5, height=1.0, direction=(0.0, 0.0, 1.0), resolution=64, capping=True)


def _rot_x(a: float) -> np.ndarray:
    c, s = math.cos(a), math.sin(a)
    return np.array([[1, 0, 0], [0, c, -s], [0, s, c]])


def _rot_y(a: float) -> np.ndarray:
    c, s = math.cos(a), math.sin(a)
    return np.array([[c, 0, s], [0, 1, 0], [-s, 0, c]])


def _rot_z(a: float) -> np.ndarray:
    c, s = math.cos(a), math.sin(a)
    return np.array([[c, -s, 0], [s, c, 0], [0, 0, 1]])


def _grid_mesh(x: np.ndarray, y: np.ndarray, z: np.ndarray) -> TriangleMesh:
    """Triangulate a (ny, nx) grid of points, two counter-clockwise (upward) triangles per cell."""
    ny, nx = z.shape
    points = np.stack([x, y, z], axis=-1).reshape(-1, 3)
    idx = np.arange(ny * nx).reshape(ny, nx)
    a, b, c, d = idx[:-1, :-1], idx[:-1, 1:], idx[1:, :-1], idx[1:, 1:]
    triangles = np.concatenate(
        [np.stack([a, b, d], -1).reshape(-1, 3), np.stack([a, d, c], -1).reshape(-1, 3)]
    )
    return TriangleMesh(points, triangles)


def floor_mesh_cells(cfg: Config) -> int:
    """Cells per patch side of the floor mesh: few for a plane (flat, slope), one per map texel for a
    curved relief."""
    return 4 if cfg.floor.shape in (FloorShape.FLAT, FloorShape.SLOPE) else cfg.caustics.map_resolution


def floor_mesh(cfg: Config, relief: np.ndarray | None, periodic: bool) -> TriangleMesh:
    """The floor as a grid mesh over the patch; on a periodic sea it reaches a margin beyond the
    patch so that photons moved by whole periods still land on it. Planar floors use few cells."""
    floor = cfg.floor
    extent = cfg.water.extent_m
    planar = floor.shape in (FloorShape.FLAT, FloorShape.SLOPE)
    cells = floor_mesh_cells(cfg)
    cell = extent / cells
    margin_cells = 0
    sample = np.linspace(-extent / 2, extent / 2, 257)
    z = None if planar else floor_relief_height(floor, relief, extent, *np.meshgrid(sample, sample))
    if z is not None and z.max() >= 0.0:  # also what keeps the margin below finite
        raise ConfigError(f"the floor's relief rises to z = {z.max():.4g} m, above the water's mean level "
                          "(z = 0); lower the relief (floor.file, floor.ripple_amplitude_m) or deepen "
                          "floor.depth_m")
    if periodic:
        relief_range = 0.0 if z is None else float(np.ptp(z))
        margin_cells = math.ceil((0.05 * extent + 4.0 * relief_range) / cell)
    coords = (np.arange(-margin_cells, cells + margin_cells + 1) * cell) - 0.5 * extent
    x, y = np.meshgrid(coords, coords)
    return _grid_mesh(x, y, floor_relief_height(floor, relief, extent, x, y))


def wall_mesh(extent_m: float, bottom_z: float, top_z: float) -> TriangleMesh:
    """The four walls of a walled pool at x, y = ±L/2, from bottom_z to top_z, facing inwards."""
    h = 0.5 * extent_m
    s = np.linspace(-h, h, WALL_CELLS + 1)
    z = np.linspace(bottom_z, top_z, 9)
    meshes = []
    for axis, sign in ((0, -1), (0, 1), (1, -1), (1, 1)):
        along, up = np.meshgrid(s, z)
        fixed = np.full_like(along, sign * h)
        x, y = (fixed, along) if axis == 0 else (along, fixed)
        m = _grid_mesh(x, y, up)
        # _grid_mesh winds (along, up) counter-clockwise; flip where that faces out of the pool.
        outward = np.zeros(3)
        outward[axis] = sign
        p = m.points[m.triangles]
        normal = np.cross(p[:, 1] - p[:, 0], p[:, 2] - p[:, 0])[0]
        tris = m.triangles if np.dot(normal, outward) < 0 else m.triangles[:, ::-1]
        meshes.append(TriangleMesh(m.points, tris))
    return _concat(meshes)


def _concat(meshes: list[TriangleMesh]) -> TriangleMesh:
    points, triangles, offset = [], [], 0
    for m in meshes:
        points.append(m.points)
        triangles.append(m.triangles + offset)
        offset += len(m.points)
    return TriangleMesh(np.concatenate(points), np.concatenate(triangles))


def albedo_spectrum(
    albedo: tuple[float, ...],
    bins: SpectralBins,
    albedo_file: str | None = None,
    base_dir: Path | None = None,
    key: str = "floor",
) -> np.ndarray:
    """(K,) reflectance per bin: from ``albedo_file`` (a measured spectrum, bin averages), a grey
    value, or linear sRGB turned into a reflectance spectrum by Mallett & Yuksel (2019)
    (colour-science's ``RGB_to_sd_Mallett2019``)."""
    if albedo_file is not None:
        from warpcaustics.optics.spectra import read_spectrum_csv

        wl, refl = read_spectrum_csv(albedo_file, base_dir, f"{key}.albedo_file", "reflectance", 1.0)
        return bins.average(wl, refl, what=f"{key}.albedo_file {albedo_file!r}")
    if len(albedo) == 1:
        return np.full(len(bins.centres_nm), float(albedo[0]))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        import colour

        sd = colour.recovery.RGB_to_sd_Mallett2019(np.asarray(albedo, np.float64))
    return bins.average(sd.wavelengths, sd.values, what="Mallett 2019 sRGB basis")


def receiver_albedos(cfg: Config, bins: SpectralBins, base_dir: Path | None) -> np.ndarray:
    """(R, K) albedo per receiver id (floor, walls, then ``receivers[i]``) and band."""
    albedos = [albedo_spectrum(cfg.floor.albedo, bins, cfg.floor.albedo_file, base_dir, "floor"),
               albedo_spectrum(WALL_ALBEDO, bins)]
    for i, r in enumerate(cfg.receivers):
        albedos.append(albedo_spectrum(r.albedo, bins, r.albedo_file, base_dir, f"receivers[{i}]"))
    return np.stack(albedos)


def floor_texel_area(cfg: Config, relief: np.ndarray | None) -> np.ndarray:
    """(M, M) true area of the floor over each map texel [m²] (two triangles on its corners)."""
    m = cfg.caustics.map_resolution
    extent = cfg.water.extent_m
    coords = np.arange(m + 1) * (extent / m) - 0.5 * extent
    x, y = np.meshgrid(coords, coords)
    p = np.stack([x, y, floor_relief_height(cfg.floor, relief, extent, x, y)], axis=-1)
    a, b, c, d = p[:-1, :-1], p[:-1, 1:], p[1:, :-1], p[1:, 1:]
    return 0.5 * (
        np.linalg.norm(np.cross(b - a, d - a), axis=-1) + np.linalg.norm(np.cross(d - a, c - a), axis=-1)
    )


class Receivers:
    """All receivers of a scene on one device: the BVH, face → receiver ids, albedos per band."""

    def __init__(
        self,
        cfg: Config,
        bins: SpectralBins,
        device: str,
        *,
        periodic: bool,
        relief: np.ndarray | None,
        meshes: tuple[TriangleMesh, ...],
        water_top_z: float,
        base_dir: Path | None = None,
    ):
        floor = floor_mesh(cfg, relief, periodic)
        parts = [floor]
        ids = [np.full(len(floor.triangles), FLOOR_ID)]
        names = ["floor"]
        if cfg.water.walled:
            bottom = float(floor.points[:, 2].min()) - 0.01 * cfg.water.extent_m
            walls = wall_mesh(cfg.water.extent_m, bottom, water_top_z)
            parts.append(walls)
            ids.append(np.full(len(walls.triangles), WALLS_ID))
        names.append("walls")
        for i, m in enumerate(meshes):
            parts.append(m)
            ids.append(np.full(len(m.triangles), FIRST_MESH_ID + i))
            names.append(f"receivers[{i}]")
        whole = _concat(parts)
        self.device = device
        self.names = names
        self.floor_face_count = len(floor.triangles)
        self.floor_vertex_count = len(floor.points)
        self._non_floor = None
        inside = np.all(np.abs(floor.points[:, :2]) <= 0.5 * cfg.water.extent_m * (1 + 1e-9), axis=1)
        self.floor_top_z = float(floor.points[inside, 2].max())
        """Highest floor point inside the patch [m]."""
        self.mesh_top_z = max((float(m.points[:, 2].max()) for m in meshes), default=-np.inf)
        """Highest point of the ``[[receivers]]`` meshes [m] (−inf without meshes)."""
        self.points = whole.points
        self.triangles = whole.triangles
        self.face_receiver_np = np.concatenate(ids).astype(np.int32)
        tri = whole.points[whole.triangles]
        self.face_centres_m = tri.mean(axis=1)
        cross = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
        self.face_area_m2 = 0.5 * np.linalg.norm(cross, axis=-1)
        unit_normals = cross / np.maximum(2.0 * self.face_area_m2, 1e-30)[:, None]
        self.albedo = receiver_albedos(cfg, bins, base_dir)
        """(R, K) diffuse albedo per receiver and band."""
        self._points_wp = wp.array(whole.points.astype(np.float32), dtype=wp.vec3, device=device)
        self._indices_wp = wp.array(whole.triangles.astype(np.int32).ravel(), dtype=wp.int32, device=device)
        self.mesh = wp.Mesh(self._points_wp, self._indices_wp)
        self.face_normal = wp.array(unit_normals.astype(np.float32), dtype=wp.vec3, device=device)
        """Unit normal of each face (winding order)."""
        self.face_receiver = wp.array(self.face_receiver_np, dtype=wp.int32, device=device)
        self.albedo_wp = wp.array(self.albedo.astype(np.float32), dtype=wp.float32, device=device)
        self.floor_texel_area_m2 = floor_texel_area(cfg, relief)

    def non_floor_mesh(self) -> tuple[np.ndarray, np.ndarray]:
        """(points, triangles) of the walls and meshes, the faces in their order here (after the
        floor's), the points renumbered to those they use."""
        if self._non_floor is None:
            tris = self.triangles[self.floor_face_count:]
            used, inverse = np.unique(tris, return_inverse=True)
            self._non_floor = (self.points[used], inverse.reshape(tris.shape))
        return self._non_floor

    @property
    def face_count(self) -> int:
        return len(self.triangles)

    def bounds(self) -> tuple[np.ndarray, np.ndarray]:
        return self.points.min(axis=0), self.points.max(axis=0)
