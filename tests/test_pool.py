"""The shallow-water pool: mass conservation, gravity-wave speed, robustness, statefulness."""

import numpy as np
import pytest
import warp as wp

import warpcaustics as wc
from warpcaustics.config import DropConfig
from warpcaustics.water.pool import ShallowWaterPool

from helpers import CONFIGS, fresnel_t_angles, subnormal_count

DEPTH_M = 1.5


def test_volume_is_conserved_with_walls(device):
    """1000 substeps of a pool sloshing after a drop: the water volume changes < 1e-6 (relative)."""
    pool = ShallowWaterPool(64, 4.0, DEPTH_M, device,
                            drops=(DropConfig(time_s=0.0, x_m=0.7, y_m=-0.4, radius_m=0.2, height_m=0.2),))
    before = pool.volume_m3()
    for _ in range(1000):
        pool.step(0.004)  # CFL 0.4 at √(g·1.7) ≈ 4.1 m/s with Δ = 6.25 cm
    moved = np.abs(pool.u.numpy()).max()
    assert moved > 1e-3, "the water must really move"
    assert abs(pool.volume_m3() / before - 1.0) < 1e-6


def test_small_disturbance_travels_at_sqrt_gh(device):
    """A small ridge of water splits into two pulses moving at c = √(g H) (non-dispersive shallow
    water), measured from the right pulse's peak between two times, within 3 %."""
    n, extent = 256, 32.0
    pool = ShallowWaterPool(n, extent, DEPTH_M, device, viscosity_m2_s=0.0)
    x = (np.arange(n) + 0.5) * extent / n - extent / 2
    ridge = DEPTH_M + 0.005 * np.exp(-0.5 * (x / 0.6) ** 2)  # σ = 4.8 cells
    pool.h = wp.array(np.tile(ridge, (n, 1)).astype(np.float32), dtype=wp.float32, device=device)

    def peak_x():
        row = pool.h.numpy()[n // 2].astype(np.float64)
        i = int(np.argmax(np.where(x > 0, row, -np.inf)))
        a, b, c = row[i - 1], row[i], row[i + 1]
        return x[i] + 0.5 * (a - c) / (a - 2 * b + c) * (extent / n)  # parabolic sub-cell peak

    pool.advance(1.0)
    x1 = peak_x()
    pool.advance(2.5)
    x2 = peak_x()
    assert (x2 - x1) / 1.5 == pytest.approx(np.sqrt(9.81 * DEPTH_M), rel=0.03)


def test_big_drop_stays_finite(device):
    """A drop half as high as the water is deep leaves no NaN and no negative depth."""
    pool = ShallowWaterPool(64, 4.0, DEPTH_M, device,
                            drops=(DropConfig(time_s=0.0, radius_m=0.25, height_m=0.5 * DEPTH_M),))
    surface = pool.at(2.0)
    h = pool.h.numpy()
    assert np.all(np.isfinite(h)) and h.min() >= 0.0
    assert np.all(np.isfinite(surface.normals.numpy()))


def test_a_blown_up_pool_is_reported_not_carried_on(device):
    """A NaN in the state (what an unstable step leaves) makes the CFL speed infinite, so the next
    advance stops with a one-line error instead of stepping on: max() alone passes NaN over."""
    pool = ShallowWaterPool(16, 4.0, DEPTH_M, device)
    pool.advance(0.05)
    h = pool.h.numpy().copy()
    h[5, 7] = np.nan
    pool.h.assign(h)
    assert not np.isfinite(pool.max_wave_speed())
    with pytest.raises(wc.WarpcausticsError, match="the pool became unstable at t = 0.05 s"):
        pool.advance(0.1)


@pytest.mark.parametrize("time_s", [1.0e7, 5.0e4])
def test_a_time_beyond_a_million_substeps_is_refused_before_stepping(time_s):
    """Reaching t = 1e7 s takes ~1e8 substeps, t = 5e4 s about 1.9e6 (twice the guard): each is
    refused at once with the estimate (the guard after a million substeps had taken minutes to fire;
    until 2026-12-07 only times past ten times it were refused up front), and the pool is left where
    it was."""
    pool = ShallowWaterPool(16, 4.0, DEPTH_M, "cpu")
    substep = 0.4 * (4.0 / 16) / np.sqrt(9.81 * DEPTH_M)  # CFL at √(g H): no slower wave in still water
    with pytest.raises(wc.WarpcausticsError, match=r"needs at least .* substeps .* render an earlier time"
                       ) as refused:
        pool.advance(time_s)
    assert float(str(refused.value).split("at least ")[1].split()[0]) == pytest.approx(time_s / substep,
                                                                                     rel=5e-3)  # 3 digits
    assert pool.time_s == 0.0 and pool.substeps == 0


def test_a_time_within_the_guard_is_not_refused_up_front():
    """The up-front refusal takes the slowest speed the pool can reach, √(g h̄): a still pool's frame
    that needs fewer substeps than the guard steps to it."""
    pool = ShallowWaterPool(8, 4.0, DEPTH_M, "cpu", viscosity_m2_s=0.0)
    substep = 0.4 * (4.0 / 8) / np.sqrt(9.81 * DEPTH_M)
    pool.advance(2000 * substep)
    assert pool.substeps == pytest.approx(2000, abs=2)


def test_a_pool_needs_two_cells_a_side():
    """One cell has no faces between walls to step; the error names the config key."""
    with pytest.raises(wc.WarpcausticsError, match="raise water.resolution"):
        ShallowWaterPool(1, 4.0, DEPTH_M, "cpu")


def test_pool_is_stateful_and_renders(device):
    """Frames step forward from the previous state; going back in time is refused; a still pool
    under an overhead sun lights its floor with E·T(0)·exp(−cD) away from the walls."""
    scene = wc.load_scene(None, {"water.model": "pool", "water.resolution": 32, "water.extent_m": 2.0,
                                 "floor.depth_m": DEPTH_M, "sun.elevation_deg": 90.0,
                                 "caustics.map_resolution": 32, "optics.wavelengths.bins": 2})
    renderer = wc.Renderer(scene, device)
    first = renderer.render(0.0)
    renderer.render(0.1)
    assert renderer.water.time_s == pytest.approx(0.1)
    with pytest.raises(wc.WarpcausticsError, match="stateful"):
        renderer.render(0.05)
    t0 = 1 - ((1.333 - 1) / (1.333 + 1)) ** 2
    expected = first.sun_irradiance * t0 * np.exp(-first.attenuation_per_m * DEPTH_M)
    inner = first.floor_irradiance[:, 2:-2, 2:-2]
    np.testing.assert_allclose(inner, np.broadcast_to(expected[:, None, None], inner.shape), rtol=1e-5)


def test_wave_pool_energy_decays_at_the_damping_rate(device):
    """Damped wave equation: discrete wave energy decays as e^(−γt) (γ = 0.5 /s, within 2 %), and
    is conserved within 1 % over 1 s without damping."""
    from warpcaustics.water.wavepool import WaveEquationPool

    bump = (DropConfig(time_s=0.0, radius_m=0.15, height_m=0.02),)
    for gamma in (0.5, 0.0):
        pool = WaveEquationPool(128, 4.0, DEPTH_M, device, damping_per_s=gamma, drops=bump)
        pool.advance(0.3)
        e1, t1 = pool.energy(), pool.time_s
        pool.advance(1.3)
        e2, t2 = pool.energy(), pool.time_s
        if gamma > 0:
            assert np.log(e1 / e2) / (t2 - t1) == pytest.approx(gamma, rel=0.02)
        else:
            assert e2 == pytest.approx(e1, rel=0.01)


def test_wave_pool_normals_match_the_bump_gradient(device):
    """The wave pool's normals (central differences of η) match the analytic gradient of the Gaussian
    bump it starts from, with the second-order error of central differences: the worst normal
    error falls about fourfold when the grid is refined twofold."""
    from warpcaustics.water.wavepool import WaveEquationPool

    extent, sigma, height = 2.0, 0.12, 0.03
    errors = []
    for n in (96, 192):
        bump = DropConfig(time_s=0.0, x_m=0.2, y_m=-0.1, radius_m=sigma, height_m=height)
        pool = WaveEquationPool(n, extent, DEPTH_M, device, drops=(bump,))
        surface = pool.at(0.0)
        p = surface.positions.numpy().astype(np.float64)
        dx, dy = p[..., 0] - 0.2, p[..., 1] + 0.1
        eta = height * np.exp(-0.5 * (dx * dx + dy * dy) / sigma**2)
        expected = np.stack([eta * dx / sigma**2, eta * dy / sigma**2, np.ones_like(eta)], -1)
        expected /= np.linalg.norm(expected, axis=-1, keepdims=True)
        np.testing.assert_allclose(p[..., 2], eta, atol=1e-6)
        errors.append(np.abs(surface.normals.numpy() - expected).max())
    # Central differences err by η_xxx Δ²/6 + O(Δ⁴); for the Gaussian, max |η_xxx| = (h/σ³) max
    # |3u − u³| e^{−u²/2} (u = x/σ), 1.7e-3 at n = 96. Normalising only shrinks the error.
    u = np.linspace(0.0, 6.0, 60001)
    bound = height / sigma**3 * np.abs((3 * u - u**3) * np.exp(-0.5 * u * u)).max() * (extent / 96) ** 2 / 6
    assert errors[0] < 1.05 * bound
    assert 3.5 < errors[0] / errors[1] < 4.5


def test_wave_pool_ridge_travels_at_c(device):
    """A ridge in the wave pool splits into pulses moving at c = √(g·depth), within 3 %."""
    from warpcaustics.water.wavepool import WaveEquationPool

    n, extent = 256, 32.0
    pool = WaveEquationPool(n, extent, DEPTH_M, device, damping_per_s=0.0)
    x = (np.arange(n) + 0.5) * extent / n - extent / 2
    ridge = np.tile(0.005 * np.exp(-0.5 * (x / 0.6) ** 2), (n, 1)).astype(np.float32)
    pool.eta = wp.array(ridge, dtype=wp.float32, device=device)
    pool.eta_prev = wp.array(ridge, dtype=wp.float32, device=device)

    def peak_x():
        row = pool.eta.numpy()[n // 2].astype(np.float64)
        i = int(np.argmax(np.where(x > 0, row, -np.inf)))
        a, b, c = row[i - 1], row[i], row[i + 1]
        return x[i] + 0.5 * (a - c) / (a - 2 * b + c) * (extent / n)

    pool.advance(1.0)
    x1, t1 = peak_x(), pool.time_s
    pool.advance(2.5)
    x2, t2 = peak_x(), pool.time_s
    assert (x2 - x1) / (t2 - t1) == pytest.approx(np.sqrt(9.81 * DEPTH_M), rel=0.03)


def test_moving_body_pushes_the_water(device):
    """A disc moving on a circle drags the water under it along (mean velocity inside the disc
    ≥ half the body's), raises a bow wave ahead of it and a trough behind, and keeps the volume."""
    from warpcaustics.config import BodyConfig

    body = BodyConfig(radius_m=0.2, path_radius_m=1.0, period_s=4.0)
    pool = ShallowWaterPool(96, 4.0, DEPTH_M, device, body=body)
    before = pool.volume_m3()
    surface = pool.at(1.0)
    centre, velocity = pool.body_state(pool.time_s)
    speed = np.linalg.norm(velocity)
    ahead = centre + 1.8 * body.radius_m * velocity / speed
    behind = centre - 1.8 * body.radius_m * velocity / speed
    n, cell = 96, 4.0 / 96
    eta = surface.positions.numpy()[..., 2]

    def at(p):
        return eta[int((p[1] + 2.0) / cell), int((p[0] + 2.0) / cell)]

    assert at(ahead) > 0.01 > -0.01 > at(behind)
    x = (np.arange(n) + 0.5) * cell - 2.0
    xx, yy = np.meshgrid(x, x)
    inside = np.hypot(xx - centre[0], yy - centre[1]) < body.radius_m
    u_c = 0.5 * (pool.u.numpy()[:, :-1] + pool.u.numpy()[:, 1:])
    v_c = 0.5 * (pool.v.numpy()[:-1] + pool.v.numpy()[1:])
    along = (u_c[inside] * velocity[0] + v_c[inside] * velocity[1]) / speed
    assert along.mean() > 0.5 * speed
    assert abs(pool.volume_m3() / before - 1.0) < 1e-6


def test_walled_pool_floor_flux(device):
    """Still water in a walled pool: with an overhead sun the floor is lit evenly to the walls and
    receives E·T(0)·L²; with an oblique sun the light shifted beyond the walls by D·tanθ_t is lost,
    leaving exactly the overlap (L − s_x)(L − s_y) of the shifted square (1e-5)."""
    for elevation, azimuth in ((90.0, 0.0), (50.0, 30.0)):
        scene = wc.load_scene(None, {"water.model": "pool", "water.resolution": 32, "water.extent_m": 2.0,
                                     "floor.depth_m": DEPTH_M, "sun.elevation_deg": elevation,
                                     "sun.azimuth_deg": azimuth, "optics.water_type": "none",
                                     "caustics.map_resolution": 40, "optics.wavelengths.bins": 1,
                                     "sun.angular_diameter_deg": 0.0})  # the overlap is a point sun's
        result = wc.render(scene, device=device)
        theta = np.radians(90.0 - elevation)
        theta_t = np.arcsin(np.sin(theta) / 1.333)
        shift = DEPTH_M * np.tan(theta_t) * np.abs([np.cos(np.radians(azimuth)), np.sin(np.radians(azimuth))])
        beam = result.sun_irradiance[0] * np.cos(theta) * fresnel_t(theta) * 4.0
        expected = beam * (2.0 - shift[0]) * (2.0 - shift[1]) / 4.0
        assert result.floor_flux_w_nm[0] == pytest.approx(expected, rel=1e-5)
        if elevation == 90.0:
            floor = result.floor_irradiance[0]
            np.testing.assert_allclose(floor, floor.mean(), rtol=1e-5)  # lit evenly up to the walls


def fresnel_t(theta):
    return fresnel_t_angles(np.array([theta]), 1.0, 1.333)[0]


def test_drops_during_the_run_add_their_volume(device):
    """Stepping with advance() through drops at t > 0 (one removing water): the volume changes by
    exactly the drops' volumes (the sampled Gaussians), nothing else (1e-6)."""
    drops = (DropConfig(time_s=0.2, x_m=0.5, radius_m=0.15, height_m=0.05),
             DropConfig(time_s=0.45, x_m=-0.6, y_m=0.3, radius_m=0.1, height_m=-0.03))
    pool = ShallowWaterPool(64, 4.0, DEPTH_M, device, drops=drops)
    before = pool.volume_m3()
    pool.advance(0.8)
    x = (np.arange(64) + 0.5) * 4.0 / 64 - 2.0
    xx, yy = np.meshgrid(x, x)
    added = sum(d.height_m * np.exp(-0.5 * ((xx - d.x_m) ** 2 + (yy - d.y_m) ** 2) / d.radius_m**2).sum()
                for d in drops) * (4.0 / 64) ** 2
    assert pool.volume_m3() == pytest.approx(before + added, rel=1e-6)


def test_wave_pool_drop_keeps_the_troughs(device):
    """A drop into a moving wave pool adds its bump and nothing else: troughs stay negative and the
    mean elevation rises by the bump's volume (a negative drop lowers it)."""
    from warpcaustics.water.wavepool import WaveEquationPool

    for height in (0.002, -0.002):
        drops = (DropConfig(time_s=0.0, radius_m=0.15, height_m=0.02),
                 DropConfig(time_s=0.5, x_m=0.5, radius_m=0.1, height_m=height))
        pool = WaveEquationPool(64, 4.0, DEPTH_M, device, damping_per_s=0.0, drops=drops)
        pool.advance(0.5 - 0.5 * pool.dt)
        before = pool.eta.numpy().astype(np.float64).copy()
        pool.advance(0.5 + 0.5 * pool.dt)  # one step, then the drop
        after = pool.eta.numpy().astype(np.float64)
        x = (np.arange(64) + 0.5) * 4.0 / 64 - 2.0
        xx, yy = np.meshgrid(x, x)
        bump = (height * np.exp(-0.5 * ((xx - 0.5) ** 2 + yy**2) / 0.1**2)).sum()
        assert before.min() < -1e-4 and after.min() < -1e-4
        # The wave step conserves Σ η with mirror walls; the drop adds its bump.
        assert after.sum() - before.sum() == pytest.approx(bump, rel=1e-3)


def test_pool_over_a_floor_relief_keeps_still_water_still_and_its_volume(device):
    """A pool over a 10° slope (the floor the photons light is the pool's depth map): still water
    stays exactly still (gravity pushes on ∇η, not on ∇h), and after a drop the volume is kept."""
    overrides = {"caustics.method": "photons", "water.resolution": 64, "caustics.map_resolution": 64,
                 "floor.shape": "slope", "floor.slope_deg": 10.0, "floor.slope_azimuth_deg": 30.0}
    still = wc.Renderer(wc.load_scene(CONFIGS / "pool.toml", {**overrides, "water.drops": []}), device)
    depth = still.water.floor_depth.numpy()
    assert depth.max() - depth.min() > 0.5  # the depth map really varies
    result = still.render(1.0)
    assert still.water.substeps > 100
    assert np.abs(result.surface_positions[..., 2]).max() < 1e-6
    pool = ShallowWaterPool.from_config(
        wc.load_scene(CONFIGS / "pool.toml", {**overrides, "water.drops": [
            {"time_s": 0.0, "x_m": 0.5, "y_m": 0.2, "radius_m": 0.2, "height_m": 0.1}]}).config, device)
    before = pool.volume_m3()
    for _ in range(500):
        pool.step(0.004)
    assert np.abs(pool.u.numpy()).max() > 1e-3
    assert abs(pool.volume_m3() / before - 1.0) < 1e-6


def test_pool_refuses_a_floor_that_reaches_the_water():
    """A relief that breaks the surface is a one-line error naming floor.shape, not a crash."""
    scene = wc.load_scene(CONFIGS / "pool.toml", {"caustics.method": "photons", "floor.shape": "slope",
                                                "floor.slope_deg": 50.0})
    with pytest.raises(wc.WarpcausticsError, match="floor.shape = 'slope' reaches the water surface"):
        wc.Renderer(scene, "cpu")


def test_cells_per_thread_do_not_change_the_substep(device):
    """The substep's kernels take a run of cells per thread (a whole row on the CPU, one cell on the
    GPU): the same pool stepped with one cell per thread, with runs that start and end inside rows
    (3, 5, 6, 47: among them runs holding just the east wall face, and just the last cell of an h
    or v row), and with whole rows is the same, bit for bit, after drops and 50 substeps; on the
    smallest pool the config allows (4²) and on 48²."""
    drops = (DropConfig(time_s=0.0, x_m=0.3, y_m=-0.2, radius_m=0.2, height_m=0.3),)
    for n in (4, 48):
        spans = (1, 3, 5, 6, 47, n + 1)
        pools = [ShallowWaterPool(n, 4.0, 1.5, device, drops=drops) for _ in spans]
        for pool, span in zip(pools, spans):
            pool._span = span
            pool.advance(0.02)
            for _ in range(50):
                pool.step(0.004)
        for pool in pools[1:]:
            for name in ("h", "u", "v"):
                np.testing.assert_array_equal(getattr(pools[0], name).numpy(), getattr(pool, name).numpy())
        assert np.abs(pools[0].h.numpy() - 1.5).max() > 1e-3  # the water moved


def test_substep_is_the_numpy_baseline_scheme():
    """The benchmark's numpy substep (benchmarks/pool_step.py: vectorised, float32 throughout, in the
    kernels' order of operations) and the kernels do the same scheme: from a sloshing state, one
    substep gives the same depths and velocities to the bit, at 64² and at 96²."""
    from benchmarks.pool_step import _dt, _pool, numpy_step

    for n in (64, 96):
        pool = _pool(n, "cpu")
        dt = _dt(pool)
        h, u, v = (a.numpy().copy() for a in (pool.h, pool.u, pool.v))
        h1, u1, v1 = numpy_step(h, u, v, pool.floor_depth.numpy(), dt, pool.cell_m, pool.viscosity)
        pool.step(dt)
        assert max(np.abs(u1).max(), np.abs(v1).max()) > 1e-3  # the water moves
        for name, ref in (("h", h1), ("u", u1), ("v", v1)):
            np.testing.assert_array_equal(getattr(pool, name).numpy(), ref, err_msg=f"{name} at {n}²")


def test_slow_faces_rest_instead_of_going_subnormal(monkeypatch):
    """The advection's numerical diffusion gives a wave front tails that fall towards zero; left
    alone, float32 holds them as subnormal numbers (slow on x86 CPUs). 64 substeps after the first
    drop at 128², the kernels' velocities hold none, while the numpy twin of the same scheme with
    the rest speed at 0 holds some; the depths are the same to the bit and the velocities differ
    by the order of REST_SPEED (a face set to rest passes its difference on to its neighbours
    through the advection and the Laplacian)."""
    from warpcaustics.kernels.water.pool import REST_SPEED

    import benchmarks.pool_step as twin
    from benchmarks.pool_step import _dt

    scene = wc.load_scene(CONFIGS / "pool.toml", {"water.resolution": 128})
    pool = ShallowWaterPool.from_config(scene.config, "cpu")
    dt = _dt(pool)
    h, u, v = (a.numpy().copy() for a in (pool.h, pool.u, pool.v))
    monkeypatch.setattr(twin, "REST_SPEED", 0.0)
    for _ in range(64):
        pool.step(dt)
        h, u, v = twin.numpy_step(h, u, v, pool.floor_depth.numpy(), dt, pool.cell_m, pool.viscosity)
    assert subnormal_count(u) + subnormal_count(v) > 0  # what the rest speed avoids
    assert subnormal_count(pool.u.numpy()) + subnormal_count(pool.v.numpy()) == 0
    np.testing.assert_array_equal(pool.h.numpy(), h)
    assert np.abs(pool.u.numpy() - u).max() < 10 * REST_SPEED
    assert np.abs(pool.v.numpy() - v).max() < 10 * REST_SPEED


def test_a_nan_velocity_stays_nan_and_slow_faces_rest(device):
    """The force kernel keeps a NaN velocity NaN (so the CFL check sees a blow-up), sets a face
    slower than REST_SPEED to rest, and keeps one just above it."""
    from warpcaustics.kernels.water import pool as pool_kernels

    n = 8
    u_adv = np.zeros((n, n + 1), np.float32)
    u_adv[1, 2] = np.nan
    u_adv[5, 3] = 0.5 * pool_kernels.REST_SPEED
    u_adv[6, 6] = 2.0 * pool_kernels.REST_SPEED
    flat = wp.array(np.ones((n, n), np.float32), dtype=wp.float32, device=device)
    out = wp.empty((n, n + 1), dtype=wp.float32, device=device)
    wp.launch(pool_kernels.accelerate_u, dim=n, device=device,
              inputs=[wp.array(u_adv, dtype=wp.float32, device=device), flat, flat, 0.01, 0.1, 0.0, n + 1],
              outputs=[out])
    u = out.numpy()
    assert np.isnan(u[1, 2])
    assert u[5, 3] == 0.0
    assert u[6, 6] == np.float32(2.0 * pool_kernels.REST_SPEED)
