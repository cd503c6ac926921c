"""A beam's bounding volume for the screen pass (Liktor & Dachsbacher 2011 §4.3, Fig. 5).

A beam's sides are bilinear patches, which no finite set of triangles bounds exactly, so a
rasteriser draws a convex volume around the beam and tests each pixel it covers. Three volumes,
chosen by ``caustics.beam_bounds``; each is given by a lower triangle (the base) and an upper one,
joined by three corner lines:

- ``hull`` (:data:`HULL`): the convex hull of the base and end vertices. It holds the side patches,
  as each lies in the hull of its four corners; when it is consistent this is the paper's
  6-triangle volume (each base edge with one end vertex, each end edge with one base vertex).
- ``prism`` (:data:`PRISM`): the touching planes below, capped by the plane through the three end
  vertices (the prism measured by issue 6's benchmark).
- ``ernst`` (:data:`ERNST`): Ernst et al. 2005's bounding prism as §4.3 gives it: "three touching
  planes are constructed, each containing one edge of the base triangle, and one of the top
  vertices such that the entire beam lies in the negative half space of the plane. The
  intersection of these planes then yields the edges of the bounding volume." It is capped, in
  Ernst's beam space (§4.3's area function: y along the base triangle's normal), by the plane
  parallel to the base at the farthest end vertex's y.

Where a touching plane does not exist (the ends and the opposite base vertex span more than a
half-turn about the edge: a beam that flips over at a focus) or a corner line does not reach the
cap in front of the base, the prism is not a bounded convex volume; the beam then takes the hull,
and the pass counts it.
"""

import warp as wp

wp.set_module_options({"enable_backward": False})

HULL = wp.constant(0)
PRISM = wp.constant(1)
ERNST = wp.constant(2)


@wp.func
def touching_plane(vi: wp.vec3, vj: wp.vec3, vk: wp.vec3, ends: wp.mat33) -> wp.vec3:
    """Inward normal of a plane through the base edge (vi, vj) and one end vertex that has all
    three end vertices (rows of ``ends``) and the opposite base vertex ``vk`` on its inner side;
    the zero vector where none does."""
    u = vj - vi
    inward = vk - vi
    for c in range(3):
        n = wp.cross(u, ends[c] - vi)
        if wp.dot(n, inward) < 0.0:
            n = -n
        ok = int(wp.length_sq(n) > 0.0)
        for m in range(3):
            r = ends[m] - vi
            if wp.dot(r, n) < -1.0e-5 * wp.length(n) * wp.length(r):
                ok = 0
        if ok == 1:
            return n
    return wp.vec3(0.0)


@wp.func
def bound_corners(
    base: wp.array2d[wp.vec3],
    direction: wp.array2d[wp.vec3],
    end_m: wp.array2d[wp.float32],
    b: int,
    shift: wp.vec3,
    kind: int,
):
    """(lower, upper, used): the rows of ``lower`` and ``upper`` are the volume's corners i = 0, 1, 2,
    corner line i joining ``lower[i]`` to ``upper[i]``; ``used`` is 0 where the beam fell back to
    the hull."""
    v0 = base[b, 0] + shift
    v1 = base[b, 1] + shift
    v2 = base[b, 2] + shift
    lower = wp.mat33(v0[0], v0[1], v0[2], v1[0], v1[1], v1[2], v2[0], v2[1], v2[2])
    ends = wp.mat33()
    for i in range(3):
        ends[i] = lower[i] + end_m[b, i] * direction[b, i]
    if kind == HULL:
        return lower, ends, 1
    sides = wp.mat33()  # row i: the touching plane of edge (i, i + 1)
    for i in range(3):
        n = touching_plane(lower[i], lower[(i + 1) % 3], lower[(i + 2) % 3], ends)
        if wp.length_sq(n) == 0.0:
            return lower, ends, 0
        sides[i] = n
    along = direction[b, 0] + direction[b, 1] + direction[b, 2]
    if kind == PRISM:
        cap_point = (ends[0] + ends[1] + ends[2]) / 3.0
        cap_normal = wp.cross(ends[1] - ends[0], ends[2] - ends[0])
    else:
        cap_normal = wp.cross(v1 - v0, v2 - v0)
        if wp.dot(cap_normal, along) < 0.0:
            cap_normal = -cap_normal
        far = float(-1.0e30)
        for m in range(3):
            far = wp.max(far, wp.dot(ends[m] - v0, cap_normal))
        cap_point = v0 + cap_normal * (far / wp.length_sq(cap_normal))
    upper = wp.mat33()
    for i in range(3):
        line = wp.cross(sides[(i + 2) % 3], sides[i])  # the sides meeting at base vertex i
        if wp.dot(line, along) < 0.0:
            line = -line
        denom = wp.dot(line, cap_normal)
        if denom == 0.0:
            return lower, ends, 0
        t = wp.dot(cap_point - lower[i], cap_normal) / denom
        if not (t > 0.0 and wp.isfinite(t)):
            return lower, ends, 0
        upper[i] = lower[i] + t * line
    return lower, upper, 1
