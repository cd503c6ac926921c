"""The CV(z) profile of several runs of ``warpcaustics field darecki2011`` in one figure:
``python -m benchmarks.darecki_figure OUT.png CSV [CSV ...]``.

The converged profile comes from two runs (docs/validation.md): the near depths on an 8 m patch of
3.9 mm cells with a 0.4 m window, the deep ones on a 32 m patch of 7.8 mm cells with a 2 m window.
This reads their ``darecki2011.csv`` files, puts their rows in order of depth (a depth in two files:
the later file's) and draws them with the command's own plot
(:func:`warpcaustics.batch.field.darecki2011.plot_profile`).
"""

from __future__ import annotations

import argparse
import csv
import sys
from pathlib import Path


def read_rows(paths: list[Path]) -> list[dict]:
    """The rows of the CSVs, numbers as floats (an empty cell as None), by depth then band."""
    rows = {}
    for path in paths:
        with path.open() as fh:
            for r in csv.DictReader(fh):
                row = {k: (float(v) if v not in ("", None) else None) for k, v in r.items()}
                rows[(row["depth_m"], row["wavelength_nm"])] = row
    return [rows[k] for k in sorted(rows)]


def main(argv: list[str] | None = None) -> int:
    from warpcaustics.batch.field.darecki2011 import plot_profile

    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("png", type=Path, help="the figure to write")
    parser.add_argument("csv", type=Path, nargs="+", help="darecki2011.csv files of the field command")
    args = parser.parse_args(argv)
    plot_profile(read_rows(args.csv), args.png)
    print(f"wrote {args.png}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
