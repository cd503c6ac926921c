"""Shah's Newton–Raphson intersection (``caustics.intersection = "newton"``) against the exact BVH
hits: its convergence on a slope and a sphere, and where a walled pool's light lands."""

from pathlib import Path

import numpy as np
import pytest
from test_photons import PHOTONS

import warpcaustics as wc

from helpers import CONFIGS


def newton_errors(scene_overrides, iterations, receiver=0, device="cpu"):
    """Statistics of |Newton hit − exact hit| [m] for each k in ``iterations`` over the photons whose
    exact hit is on receiver id ``receiver``: dicts of mean, median, p95 and ``within_texel`` (the
    share closer than one light-view texel); and that texel's size [m]. ``scene_overrides`` may
    name a ``config`` (default the ocean) and the ``time_s`` rendered."""
    overrides = dict(scene_overrides)
    config = overrides.pop("config", CONFIGS / "ocean.toml")
    time_s = overrides.pop("time_s", 0.0)
    base = {
        **PHOTONS,
        "water.resolution": 64,
        "caustics.map_resolution": 64,
        "optics.wavelengths": "rgb",
        "caustics.photon_subdivisions": 2,
        "sun.angular_diameter_deg": 0.0,  # Newton's guesses come from the sun's centre
        **overrides,
    }
    exact = wc.Renderer(wc.load_scene(config, {**base, "caustics.intersection": "exact"}), device)
    exact.render(time_s)
    hit = exact.method.caustics[0].hit.numpy().copy()
    face = exact.method.caustics[0].face.numpy().copy()
    on_receiver = exact.method.receivers.face_receiver_np[np.maximum(face, 0)] == receiver
    out = []
    for k in iterations:
        newton = {**base, "caustics.intersection": "newton", "caustics.newton_iterations": k}
        r = wc.Renderer(wc.load_scene(config, newton), device)
        r.render(time_s)
        ok = (face >= 0) & on_receiver & (r.method.caustics[0].face.numpy() >= 0)
        err = np.linalg.norm(r.method.caustics[0].hit.numpy()[ok] - hit[ok], axis=1)
        out.append(
            {
                "mean": float(err.mean()),
                "median": float(np.median(err)),
                "p95": float(np.percentile(err, 95)),
                "within_texel": float(np.mean(err < r.method.caustics[0].view.texel_m)),
            }
        )
    return out, r.method.caustics[0].view.texel_m


SLOPE = {
    "config": CONFIGS / "pool.toml",
    "time_s": 0.6,
    "floor.shape": "slope",
    "floor.slope_deg": 15.0,
    "floor.slope_azimuth_deg": 30.0,
    "sun.elevation_deg": 90.0,
}
"""A 15° slope under the shallow-water pool, 0.6 s after its drops (a slope does not tile a sea),
sun at the zenith."""
SPHERE = {"receivers": [{"mesh": "sphere", "scale": 3.0, "translate_m": [0.0, 0.0, -2.5]}]}


def test_newton_hits_converge_on_a_sloped_floor():
    """Shah's iteration on a 15° slope: from the flat-floor start, the error in the hit falls by more
    than 10× per iteration (bilinear look-ups make a plane exact) down to float32 rounding."""
    errors, texel = newton_errors(SLOPE, [0, 1, 2, 3])
    means = [e["mean"] for e in errors]
    assert all(b < 0.1 * a for a, b in zip(means[:3], means[1:3]))
    assert errors[3]["p95"] < 1e-3 * texel


def test_newton_hits_converge_on_a_sloped_floor_under_an_oblique_sun():
    """The same slope with the sun 80° high: the light view, along the refracted sun and through the
    pool's walls from outside, is not hidden by them, so the photons converge to float32 rounding
    (all of them, measured; docs/validation.md)."""
    errors, texel = newton_errors({**SLOPE, "sun.elevation_deg": 80.0}, [3])
    assert errors[0]["within_texel"] > 0.99
    assert errors[0]["p95"] < 1e-3 * texel


def test_newton_hits_approach_the_exact_hits_on_a_mesh():
    """On a sphere the median error falls with every k and nearly all photons converge to within a
    light-view texel. The rest land where the light view (along the refracted sun) does not see the
    sphere, or cycle between sphere and floor at the silhouette: caustics mapping cannot find
    those, so the mean stays large (docs/validation.md)."""
    errors, texel = newton_errors(SPHERE, [0, 1, 2, 3, 5], receiver=2)
    medians = [e["median"] for e in errors]
    assert all(b < a for a, b in zip(medians, medians[1:]))
    assert errors[-1]["within_texel"] > 0.95


def pool_flux_by_intersection(elevation_deg: float, config: str | Path = CONFIGS / "pool.toml",
                              device: str = "cpu") -> dict:
    """Floor and wall flux (bands summed) [W nm^-1] of a walled pool 0.6 s after its drops with
    exact and with Newton hits (k = 3, 1024² light view), sun at ``elevation_deg``, no absorption;
    and the transmitted flux."""
    out = {}
    for mode in ("exact", "newton"):
        scene = wc.load_scene(config, {
            **PHOTONS, "caustics.intersection": mode, "sun.elevation_deg": elevation_deg,
            "sun.angular_diameter_deg": 0.0, "water.resolution": 64, "caustics.map_resolution": 64,
            "optics.wavelengths": "rgb", "optics.water_type": "none"})
        r = wc.Renderer(scene, device).render(0.6)
        walls = r.face_flux_w_nm[r.face_receiver == 1].sum(dtype=np.float64)
        out[mode] = {"floor": float(r.floor_flux_w_nm.sum(dtype=np.float64)), "walls": float(walls)}
        out["transmitted"] = float(r.transmitted_flux_w_nm.sum(dtype=np.float64))
    return out


@pytest.mark.parametrize(("config", "elevation_deg"),
                         [("pool.toml", 20.0), ("pool.toml", 40.0), ("pool.toml", 70.0),
                          ("wavepool.toml", 30.0)])
def test_newton_puts_the_pools_light_on_the_same_receivers_as_exact_hits(config, elevation_deg):
    """Shah's light view looks along the sun's refracted direction and passes through the walls of a
    pool where it meets them from outside (light enters through the water, not through them), so
    the walls, which stand 1 m above the water, hide no floor or wall that refracted light reaches.
    Floor and wall flux then match the exact hits to 0.5 % of the transmitted flux: the photons that
    may go to the other receiver or be lost are those within about a light-view texel (4–6 mm) of
    an edge (the floor–wall corner, a wall's edge in the view), about 0.3 % of the floor's flux.
    (Viewed along the sun in air, two thirds of the floor's flux went to the walls at 40° in
    pool.toml — issue 28's report, kept here as its regression case — and all of it at 20°.)
    wavepool.toml has the larger waves: crests send some light (0.06 % at 30°) onto the walls
    above the water at rest."""
    f = pool_flux_by_intersection(elevation_deg, CONFIGS / config)
    for part in ("floor", "walls"):
        assert abs(f["newton"][part] - f["exact"][part]) < 5e-3 * f["transmitted"], part
    assert f["exact"]["floor"] + f["exact"]["walls"] == pytest.approx(f["transmitted"], rel=1e-4)
    assert f["newton"]["floor"] + f["newton"]["walls"] == pytest.approx(f["transmitted"], rel=5e-3)
