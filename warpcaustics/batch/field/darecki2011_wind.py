"""Field comparison: the CV of downwelling irradiance against wind and wavelength, Darecki et al. (2011).

Darecki, Stramski & Sokolski (2011), J. Geophys. Res. 116, C00H09, Fig. 13b: the CV of Ed at about
1 m (0.91-1.25 m) at 410, 443, 488, 532, 610 and 670 nm on five days of different wind, 3.9 to
10.3 m/s, Santa Barbara Channel, September 2008, sun 42-46° from the zenith, c(555) 0.55-0.78 1/m,
a 2.5 mm collector. The values come from the ``jerlov`` package (``darecki2011_spectral_cv``).

``warpcaustics field darecki2011_wind SCENE --out DIR`` renders SCENE
(``configs/field/darecki2011_wind.toml``: the middle of each of the record's ranges) at each day's
wind as one resumable sweep, pools each wind's frames per band and writes ``darecki2011_wind.csv``
and ``darecki2011_wind.png``: CV against wavelength per wind, as the paper plots it, and the model
over the measurement against the wind per band. It is the wind axis of issue 27's budget at a
second site, and the red's share of the contrast (issue 32) at six bands. The model's CV is
spatial, the measurement's temporal, as in :mod:`.darecki2011`.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from warpcaustics.batch.field.common import band_row, checked_arguments
from warpcaustics.batch.field.darecki2011 import PLOT_NEEDS, beam_attenuation, render_record
from warpcaustics.io.files import atomic_path, pyplot, write_csv

POINT_KEYS = ("water.wind_speed_m_s",)


def record():
    """The measured spectra (``jerlov.darecki2011_spectral_cv``)."""
    import jerlov

    return jerlov.darecki2011_spectral_cv()


@checked_arguments
def run_darecki2011_wind(
    scene: str | Path,
    out: str | Path,
    *,
    winds: tuple[float, ...] | None = None,
    frames: int = 3,
    frame_interval_s: float = 5.0,
    workers: int = 1,
    device: str | None = None,
    quick: bool = False,
    quiet: bool = False,
    force: bool = False,
    overrides: dict | None = None,
) -> dict[str, Path]:
    """Render SCENE at each of the record's winds (or ``winds`` of them) as one resumable sweep into
    ``out``, pool each wind's frames per band and write ``darecki2011_wind.csv`` and
    ``darecki2011_wind.png``. The frames are ``frame_interval_s`` apart (5 s: longer than the peak
    waves' period, so each frame samples the largest scales anew)."""
    rec = record()
    config, points = render_record(
        scene, out, rec, POINT_KEYS[0], rec.wind_m_s, winds, ("--winds", "wind [m/s]"), frames=frames,
        frame_interval_s=frame_interval_s, workers=workers, device=device, quick=quick, quiet=quiet,
        force=force, overrides=overrides)
    c555 = beam_attenuation(config, 555.0)
    rows = []
    for wind, k, bands, _ in points:
        for j, band in enumerate(bands):
            measured = float(rec.cv[k, j])
            rows.append({"wind_m_s": wind, "day": rec.days[k], "wavelength_nm": float(rec.wavelengths_nm[j]),
                         "measured_cv": round(measured, 4), **band_row(band, measured),
                         "model_depth_m": config.floor.depth_m,
                         "model_sun_zenith_deg": round(90.0 - config.sun.elevation_deg, 3),
                         "model_c555_per_m": round(c555, 4),
                         "measured_c555_per_m": "-".join(f"{c:g}" for c in rec.beam_attenuation_555)})
    out = Path(out)
    paths = {"csv": out / "darecki2011_wind.csv", "png": out / "darecki2011_wind.png"}
    write_csv(paths["csv"], rows)
    _plot(rows, paths["png"], quick)
    return paths


def _plot(rows: list[dict], path: Path, quick: bool) -> None:
    """Left: CV against wavelength per wind, measured (solid) and model (dashed), as Fig. 13b.
    Right: the model over the measurement against the wind, per band."""
    plt = pyplot(PLOT_NEEDS)
    winds = sorted({r["wind_m_s"] for r in rows})
    bands = sorted({r["wavelength_nm"] for r in rows})
    fig, (left, right) = plt.subplots(1, 2, figsize=(11.0, 4.4))
    colours = plt.get_cmap("viridis")(np.linspace(0.0, 0.9, len(winds)))
    for colour, u in zip(colours, winds):
        rs = [r for r in rows if r["wind_m_s"] == u]
        nm = [r["wavelength_nm"] for r in rs]
        left.plot(nm, [r["measured_cv"] for r in rs], "o-", color=colour, label=f"{u:g} m/s, measured")
        left.errorbar(nm, [r["model_cv"] for r in rs], yerr=[r["model_cv_frame_sd"] for r in rs], fmt="s--",
                      color=colour, capsize=2, label=f"{u:g} m/s, model")
    left.set_xlabel("wavelength [nm]")
    left.set_ylabel("CV of Ed")
    left.set_title("Darecki et al. 2011, Fig. 13b (solid) and the model (dashed)", fontsize=9)
    left.legend(fontsize=6, ncol=2)
    left.grid(alpha=0.3)
    band_colours = plt.get_cmap("plasma")(np.linspace(0.0, 0.85, len(bands)))
    for colour, nm in zip(band_colours, bands):
        rs = [r for r in rows if r["wavelength_nm"] == nm]
        right.plot([r["wind_m_s"] for r in rs], [r["model_over_measured"] for r in rs], "s-", color=colour,
                   label=f"{nm:g} nm")
    right.axhline(1.0, color="k", lw=0.8)
    right.set_xlabel("wind [m/s]")
    right.set_ylabel("model / measured")
    right.legend(fontsize=7)
    right.grid(alpha=0.3)
    if quick:
        fig.suptitle("--quick: coarse check of the command, not a comparison", color="tab:red")
    fig.tight_layout()
    with atomic_path(path) as tmp:
        fig.savefig(tmp, format="png", dpi=110)
    plt.close(fig)
