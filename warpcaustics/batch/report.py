"""``warpcaustics report DIR``: a sweep's ``summary.csv`` printed as a table of what varied and its
headline figures, and plotted per frame (``summary.png``)."""

from __future__ import annotations

import csv
from pathlib import Path

from warpcaustics.batch.sweep import SUMMARY
from warpcaustics.errors import WarpcausticsError
from warpcaustics.io.files import atomic_path


def _short(text: str) -> str:
    """A CSV cell for the printed table: floats to 4 significant digits."""
    try:
        value = float(text)
    except ValueError:
        return text
    return text if value.is_integer() and "." not in text else f"{value:.4g}"


STAT_AXES = (("floor_w_m2", "floor irradiance\n[W m$^{-2}$]"), ("contrast", "contrast\n(std / mean)"),
             ("cv", "CV after the\ncollector"))
"""The statistics ``warpcaustics report`` plots, one panel each, over the sweep's variants."""


BAND_COLUMNS = ("mean_", "max_")
"""Prefixes of the per-band columns (``mean_418.75nm``), which stay in the CSV."""


def varied_keys(rows: list[dict]) -> list[str]:
    """The config keys (dotted names) whose values differ between the summary's ``rows``: the
    variants' labels. A band's columns hold a dot too where its wavelength is not whole."""
    return [c for c in rows[0] if "." in c and not c.startswith(BAND_COLUMNS)
            and any(r[c] != rows[0][c] for r in rows)]


def _summary_rows(path: Path) -> list[dict]:
    """The rows of a sweep's ``summary.csv``, or one line saying why it is not one."""
    fix = "rerun the sweep with the same --out to write it again"
    try:
        with open(path, encoding="utf-8", newline="") as fh:
            rows = list(csv.DictReader(fh))
    except (OSError, UnicodeDecodeError, csv.Error) as exc:
        raise WarpcausticsError(f"{str(path)!r} cannot be read as a sweep summary "
                                f"({getattr(exc, 'strerror', None) or exc}); {fix}") from None
    needed = ("id", "frame")
    for k, row in enumerate(rows):
        missing = [c for c in needed if not row.get(c)]
        numbers = [c for c, _ in STAT_AXES if row.get(c) not in (None, "") and not _is_float(row[c])]
        if missing or numbers or None in row or None in row.values():
            what = (f"no {missing[0]!r}" if missing else f"{numbers[0]} = {row[numbers[0]]!r} is not a "
                    "number" if numbers else "a row of other length than the header")
            raise WarpcausticsError(f"{str(path)!r} is not a sweep summary (row {k + 1}: {what}); {fix}")
    return rows


def _is_float(text: str) -> bool:
    try:
        float(text)
    except ValueError:
        return False
    return True


def report_main(out: str) -> int:
    """Print ``DIR/summary.csv`` as a table and plot the floor irradiance per task."""
    if Path(out).exists() and not Path(out).is_dir():
        raise WarpcausticsError(f"{out!r} is a file; give the folder a sweep wrote (its --out)")
    path = Path(out) / SUMMARY
    if not path.exists():
        raise WarpcausticsError(
            f"{str(path)!r} does not exist; run `warpcaustics sweep ... --out {out}` first"
        )
    rows = _summary_rows(path)
    if not rows:
        print("no finished tasks")
        return 0
    # The varied keys and the headline figures; per-band columns stay in the CSV.
    fixed = {c for c in rows[0] if all(r[c] == rows[0][c] for r in rows)}
    headline = {"id", "frame", "floor_w_m2", "contrast", "render_s"}
    shown = [c for c in rows[0] if c in headline or (c not in fixed and not c.startswith(BAND_COLUMNS))]
    rows_shown = [{c: _short(r[c]) for c in shown} for r in rows]
    widths = {c: max(len(c), *(len(r[c]) for r in rows_shown)) for c in shown}
    print("  ".join(c.ljust(widths[c]) for c in shown))
    for r in rows_shown:
        print("  ".join(r[c].ljust(widths[c]) for c in shown))
    try:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        print("(pip install warpcaustics[study] for the plot)")
        return 0
    # The varied config keys (dotted names) label the x axis; the statistics are the panels' y axes.
    varied = varied_keys(rows)
    labels = [", ".join(_short(r[c]) for c in varied) or f"{r['id'][:6]} #{r['frame']}" for r in rows]
    panels = [(c, label) for c, label in STAT_AXES if c in rows[0]]
    fig, axes = plt.subplots(len(panels), 1, sharex=True, squeeze=False,
                             figsize=(max(6.0, 0.3 * len(rows) + 2.0), 1.0 + 2.0 * len(panels)))
    for ax, (column, label) in zip(axes[:, 0], panels):
        ax.bar(range(len(rows)), [float(r[column] or "nan") for r in rows])
        ax.set_ylabel(label, fontsize=8)
    axes[0, 0].set_yscale("log")
    bottom = axes[-1, 0]
    bottom.set_xticks(range(len(rows)), labels, rotation=90, fontsize=7)
    bottom.set_xlabel(" / ".join(varied) if varied else "task", fontsize=8)
    axes[0, 0].set_title(f"{Path(out).name}: {len(rows)} frames", fontsize=9)
    fig.tight_layout()
    plot = Path(out) / "summary.png"
    with atomic_path(plot) as tmp:
        fig.savefig(tmp, format="png", dpi=120)
    plt.close(fig)
    print(f"plot: {plot}")
    return 0
