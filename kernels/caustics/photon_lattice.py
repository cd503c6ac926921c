"""A photon's lattice cell on its receiver (its stratum's edges carried through refraction): the
steps from its hit to its grid neighbours' hits on the same receiver. The camera's splats
(``kernels/scene/camera/splats.py``) and the floor map's footprint splats
(``kernels/caustics/photons.py``, ``caustics.photon_splat = "footprint"``) both spread a photon over
it. Photons are indexed ``((g Q + qy) Q + qx) s² + sub`` (``kernels/caustics/photons.py``).
"""

import warp as wp

wp.set_module_options({"enable_backward": False})

MAX_CELL_SPACINGS = 16.0
"""A photon's lattice cell longer than this many surface photon spacings is not a neighbourhood
(its neighbour landed far away, past a silhouette): the photon falls back (to a Gaussian in the
camera, to its texel on the floor map)."""

MIN_CELL_ALIGNMENT = 0.7
"""A lattice cell must lie in its receiver's surface: |cos| between the cell's and the face's
normals at least this (neighbours across the edge of a box do not)."""


@wp.func
def unwrap(a: wp.vec3, b: wp.vec3, periodic: int, extent_m: float) -> wp.vec3:
    """b − a, with whole periods removed on a periodic sea (neighbours may be shifted differently)."""
    e = b - a
    if periodic != 0:
        e = e - wp.vec3(extent_m * wp.round(e[0] / extent_m), extent_m * wp.round(e[1] / extent_m), 0.0)
    return e


@wp.func
def step_sub(sub: int, quad: int, step: int, s: int):
    """(sub, quad) one photon further (``step`` = ±1) along a row of s photons per quad, carried into
    the next or previous quad."""
    sub += step
    if sub == s:
        sub = 0
        quad += 1
    if sub < 0:
        sub = s - 1
        quad -= 1
    return sub, quad


@wp.func
def on_receiver(n: int, r: int, face: wp.array[wp.int32], face_receiver: wp.array[wp.int32]) -> bool:
    """Whether photon n exists (n ≥ 0), landed, and landed on receiver r."""
    if n < 0:
        return False
    if face[n] < 0:
        return False
    return face_receiver[face[n]] == r


@wp.func
def grid_neighbour(p: int, along_v: int, step: int, quads: int, s: int, periodic: int) -> int:
    """Index of the photon one grid step (``step`` = ±1) along u (along_v = 0) or v from photon p;
    −1 past a wall."""
    sub = p % (s * s)
    cell = p / (s * s)
    qx = cell % quads
    qy = (cell / quads) % quads
    base = cell - qx - qy * quads  # first cell of this index group
    a = sub % s
    b = sub / s
    if along_v == 0:
        a, qx = step_sub(a, qx, step, s)
    else:
        b, qy = step_sub(b, qy, step, s)
    if qx == quads or qy == quads or qx < 0 or qy < 0:
        if periodic == 0:
            return -1
        qx = (qx + quads) % quads
        qy = (qy + quads) % quads
    return (base + qy * quads + qx) * s * s + b * s + a


@wp.func
def quarter_position(q: int, a: int, s: int, quads: int) -> int:
    """Along one axis of a walled pool's lattice: where photon a (of s) of quad q sits, in quarters of
    a stratum of a full surface cell (1/(4s) of a cell) from the wall; the quads at the walls are
    half cells (``fluxratio.grid_corner``), so their strata are half as wide."""
    if q == 0:
        return 2 * a + 1
    if q == quads - 1:
        return 2 * s + 4 * s * (q - 1) + 2 * a + 1
    return 2 * s + 4 * s * (q - 1) + 4 * a + 2


@wp.func
def stratum_ratio(p: int, n: int, along_v: int, quads: int, s: int, periodic: int) -> float:
    """Photon p's stratum width along u or v over its distance on the surface to grid neighbour n:
    1 on a periodic sea, where the lattice is uniform; in a walled pool the step to a neighbour
    across the seam of a wall's half-width quad is scaled by it, so that each cell spans its own
    stratum and the cells tile the floor there too (exactly 1 away from the seams)."""
    if periodic != 0:
        return 1.0
    ss = s * s
    cp = p / ss
    cn = n / ss
    qp = (cp / quads) % quads
    qn = (cn / quads) % quads
    ap = (p % ss) / s
    an = (n % ss) / s
    if along_v == 0:
        qp = cp % quads
        qn = cn % quads
        ap = (p % ss) % s
        an = (n % ss) % s
    width = 4
    if qp == 0 or qp == quads - 1:
        width = 2
    distance = wp.abs(quarter_position(qn, an, s, quads) - quarter_position(qp, ap, s, quads))
    return float(width) / float(distance)


@wp.func
def lattice_step(
    hit: wp.array[wp.vec3],
    face: wp.array[wp.int32],
    face_receiver: wp.array[wp.int32],
    p: int,
    along_v: int,
    quads: int,
    s: int,
    periodic: int,
    extent_m: float,
):
    """(e, ok): the step from photon p's hit to its next grid neighbour's along u or v, taken
    forwards, or backwards (reversed) where the forward neighbour is missing, lost or on another
    receiver; ok = 0 if neither qualifies."""
    r = face_receiver[face[p]]
    n = grid_neighbour(p, along_v, 1, quads, s, periodic)
    if on_receiver(n, r, face, face_receiver):
        ratio = stratum_ratio(p, n, along_v, quads, s, periodic)
        return unwrap(hit[p], hit[n], periodic, extent_m) * ratio, int(1)
    n = grid_neighbour(p, along_v, -1, quads, s, periodic)
    if on_receiver(n, r, face, face_receiver):
        ratio = stratum_ratio(p, n, along_v, quads, s, periodic)
        return unwrap(hit[n], hit[p], periodic, extent_m) * ratio, int(1)
    return wp.vec3(0.0), int(0)


@wp.func
def photon_lattice(
    hit: wp.array[wp.vec3],
    face: wp.array[wp.int32],
    face_receiver: wp.array[wp.int32],
    face_normal: wp.array[wp.vec3],
    p: int,
    quads: int,
    s: int,
    periodic: int,
    extent_m: float,
    spacing_m: float,
):
    """(e_u, e_v, ok): photon p's lattice cell on its receiver [m]. ok = 0 (the caller falls back) where
    no neighbour on the same receiver exists along u or v, or where the cell does not lie in the
    receiver's surface (neighbours across an edge of a box) or is implausibly large."""
    eu, ok_u = lattice_step(hit, face, face_receiver, p, 0, quads, s, periodic, extent_m)
    ev, ok_v = lattice_step(hit, face, face_receiver, p, 1, quads, s, periodic, extent_m)
    if ok_u == 0 or ok_v == 0:
        return eu, ev, int(0)
    normal = wp.cross(eu, ev)
    area = wp.length(normal)
    longest = wp.max(wp.length(eu), wp.length(ev))
    if area <= 1.0e-6 * longest * longest or longest > MAX_CELL_SPACINGS * spacing_m:
        return eu, ev, int(0)
    if wp.abs(wp.dot(normal, face_normal[face[p]])) < MIN_CELL_ALIGNMENT * area:
        return eu, ev, int(0)
    return eu, ev, int(1)
