"""The under-water pinhole camera: pixel rays, projection, the G-buffer by ray casting, and the
final shading.

Pixel (j, i) (row j from the top) looks along
``normalize(forward + x_i tan(fov/2) aspect right + y_j tan(fov/2) up)`` with
``x_i = 2 (i + ½)/W − 1`` and ``y_j = 1 − 2 (j + ½)/H``. Its solid angle is
``(2 tan(fov/2)/H)² cos³α`` (α off the optical axis), its footprint on a receiver at distance r
with normal n is ``r² Ω / |cos(ray, n)|``.
"""

import warp as wp

wp.set_module_options({"enable_backward": False})

INV_PI = 0.3183098861837907


@wp.struct
class PinholeCamera:
    position: wp.vec3
    right: wp.vec3
    up: wp.vec3
    forward: wp.vec3
    tan_half_fov: float
    aspect: float
    """Width / height."""
    width: int
    height: int


@wp.func
def pixel_ray(cam: PinholeCamera, i: int, j: int) -> wp.vec3:
    x = 2.0 * (float(i) + 0.5) / float(cam.width) - 1.0
    y = 1.0 - 2.0 * (float(j) + 0.5) / float(cam.height)
    return wp.normalize(
        cam.forward + (x * cam.tan_half_fov * cam.aspect) * cam.right + (y * cam.tan_half_fov) * cam.up
    )


@wp.func
def pixel_solid_angle(cam: PinholeCamera, ray: wp.vec3) -> float:
    side = 2.0 * cam.tan_half_fov / float(cam.height)
    c = wp.dot(ray, cam.forward)
    return side * side * c * c * c


@wp.func
def project(cam: PinholeCamera, x: wp.vec3) -> wp.vec3:
    """(column, row, distance) of point x: continuous pixel coordinates; distance < 0 behind."""
    v = x - cam.position
    z = wp.dot(v, cam.forward)
    if z <= 1.0e-6:
        return wp.vec3(-1.0, -1.0, -1.0)
    px = (wp.dot(v, cam.right) / (z * cam.tan_half_fov * cam.aspect) + 1.0) * 0.5 * float(cam.width)
    py = (1.0 - wp.dot(v, cam.up) / (z * cam.tan_half_fov)) * 0.5 * float(cam.height)
    return wp.vec3(px, py, wp.length(v))


@wp.kernel
def gbuffer(
    cam: PinholeCamera,
    mesh: wp.uint64,
    face_receiver: wp.array[wp.int32],
    position: wp.array2d[wp.vec3],
    normal: wp.array2d[wp.vec3],
    depth: wp.array2d[wp.float32],
    receiver: wp.array2d[wp.int32],
    inv_footprint: wp.array2d[wp.float32],
    depth_slack: wp.array2d[wp.float32],
    rays: wp.array2d[wp.vec3],
):
    """First receiver along each pixel's ray: position, normal facing the camera, distance,
    receiver id (−1 and depth 1e30 for none) and 1 / the pixel's footprint area there [m^-2]; and
    the unit ray itself (what the volume pass marches).
    ``depth_slack``: how much the distance of points on the receiver within the pixel's footprint
    can differ from the centre ray's, 1.5 · r · (pixel angle) · tan(incidence) [m]."""
    j, i = wp.tid()
    ray = pixel_ray(cam, i, j)
    rays[j, i] = ray
    q = wp.mesh_query_ray(mesh, cam.position, ray, 1.0e5)
    if q.result:
        n = q.normal
        if wp.dot(n, ray) > 0.0:
            n = -n
        position[j, i] = cam.position + q.t * ray
        normal[j, i] = n
        depth[j, i] = q.t
        receiver[j, i] = face_receiver[q.face]
        cos_r = wp.max(-wp.dot(n, ray), 0.02)
        inv_footprint[j, i] = cos_r / (q.t * q.t * pixel_solid_angle(cam, ray))
        pixel_angle = 2.0 * cam.tan_half_fov / float(cam.height)
        depth_slack[j, i] = 1.5 * q.t * pixel_angle * wp.sqrt(1.0 - cos_r * cos_r) / cos_r
    else:
        position[j, i] = cam.position + 1.0e5 * ray
        normal[j, i] = -ray
        depth[j, i] = 1.0e30
        receiver[j, i] = -1
        inv_footprint[j, i] = 0.0
        depth_slack[j, i] = 0.0


@wp.kernel
def shade(
    receiver: wp.array2d[wp.int32],
    depth: wp.array2d[wp.float32],
    caustic: wp.array3d[wp.float32],
    shafts: wp.array3d[wp.float32],
    albedo: wp.array2d[wp.float32],
    attenuation_per_m: wp.array[wp.float32],
    radiance: wp.array3d[wp.float32],
):
    """Radiance at the camera: a Lambertian receiver's ``albedo · E / π`` attenuated over the
    distance to the camera, plus the light shafts in front of it."""
    k, j, i = wp.tid()
    value = shafts[k, j, i]
    r = receiver[j, i]
    if r >= 0:
        value += albedo[r, k] * caustic[k, j, i] * INV_PI * wp.exp(-attenuation_per_m[k] * depth[j, i])
    radiance[k, j, i] = value
