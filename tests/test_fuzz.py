"""A fuzz of the CLI (issue 31): configs built from the schema itself and mutated, rendered through
``warpcaustics render`` in-process. The property: it either renders a tiny scene whose floor maps
and camera images (every EXR channel, the .npz) are finite and non-negative, with ``run.json``
written last, or it exits 2 with one line that names a real key (or a CLI option, or the config
file) — never a traceback, a Warp message or another exit code.

Profiles: ``ci`` (the default: 600 examples, about half a minute on 2 cores) and ``long``
(``WARPCAUSTICS_FUZZ=long``: 5000 examples; ``WARPCAUSTICS_FUZZ_EXAMPLES=N`` sets any count).
Valid draws are clamped to tiny scenes (N, M ≤ 32, ≤ 4 bands, ≤ 4 sky and disk directions) so a
render costs a fraction of a second. The causes of issue 31 stand as explicit ``@example``s
(through a subprocess in test_bad_input.py)."""

from __future__ import annotations

import contextlib
import dataclasses
import enum
import io
import math
import os
import re
import tempfile
import typing
from pathlib import Path

import numpy as np
import pytest

hypothesis = pytest.importorskip("hypothesis")
from hypothesis import HealthCheck, event, example, given, settings  # noqa: E402
from hypothesis import strategies as st  # noqa: E402

from warpcaustics import cli  # noqa: E402
from warpcaustics.config import Config  # noqa: E402
from warpcaustics.config.loading import _hints, _is_section, _tuple_item, all_keys  # noqa: E402

from helpers import CONFIGS  # noqa: E402

settings.register_profile("ci", max_examples=600, deadline=None, print_blob=True,
                          suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large])
settings.register_profile("long", parent=settings.get_profile("ci"), max_examples=5000)
_profile = os.environ.get("WARPCAUSTICS_FUZZ", "ci")
_examples = os.environ.get("WARPCAUSTICS_FUZZ_EXAMPLES")
settings.load_profile(_profile)
EXAMPLES = int(_examples) if _examples else settings().max_examples

BASES = ["ocean.toml", "pool.toml", "wavepool.toml", "procedural.toml", "flat.toml", "pool_pots.toml",
         "lens.toml", "buried_in_sand.toml"]
"""Scenes the fuzz starts from (every method and water model is one mutation away)."""

TINY = {"water.resolution": 16, "caustics.map_resolution": 16, "optics.wavelengths.bins": 2,
        "sun.disk_samples": 2, "camera.width": 16, "camera.height": 12, "output.npz": True,
        "caustics.eikonal_resolution": 16, "caustics.wave3d_resolution": 16}
"""Every example's first overrides: a tiny scene that writes its floor map as .npz too."""

CAPS = {"water.resolution": 32, "caustics.map_resolution": 32, "optics.wavelengths.bins": 4,
        "sun.disk_samples": 4, "sky.directions": 4, "camera.width": 32, "camera.height": 32,
        "caustics.eikonal_resolution": 24, "caustics.wave3d_resolution": 32,
        "caustics.newton_buffer_resolution": 64, "caustics.photon_subdivisions": 4,
        "optics.mc_samples": 2, "optics.mc_max_events": 64, "caustics.wave3d_periods": 2.0,
        "caustics.wave3d_cells_per_wavelength": 8.0, "water.procedural_octaves": 4}
"""Largest valid draw of the keys that set a render's cost."""


@dataclasses.dataclass(frozen=True)
class Leaf:
    key: str
    tp: typing.Any
    meta: dict


def _leaves(cls=Config, prefix: str = "") -> list[Leaf]:
    out = []
    for f in dataclasses.fields(cls):
        tp = _hints(cls)[f.name]
        if _tuple_item(tp) is not None:
            out.append(Leaf(f"{prefix}{f.name}", "tables", {"item": _tuple_item(tp)}))
        elif _is_section(tp):
            out += _leaves(tp, f"{prefix}{f.name}.")
        else:
            out.append(Leaf(f"{prefix}{f.name}", tp, dict(f.metadata)))
    return out


LEAVES = [leaf for leaf in _leaves() if leaf.key not in ("output.npz", "device")]
KEYS = {k.replace("[]", "") for k in all_keys()}
NAMES = KEYS | {k.rsplit(".", 1)[0] for k in KEYS if "." in k} | {k.split(".")[0] for k in KEYS}
"""What an error may name: a key, a section, or a table of keys."""
CLI_WORDS = ("--set", "--out", "--time", "--frames", "--fps", "--device", "config file", "device")


def _plain(tp):
    args = typing.get_args(tp)
    return next(a for a in args if a is not type(None)) if type(None) in args else tp


def valid_value(leaf: Leaf) -> st.SearchStrategy:
    """A value the key's own type and range allow (cost keys kept small)."""
    tp = _plain(leaf.tp)
    lo, hi, lo_open = leaf.meta.get("range", (None, None, False))
    cap = CAPS.get(leaf.key)
    if tp == "tables":
        return st.just([])
    if isinstance(tp, type) and issubclass(tp, enum.Enum):
        return st.sampled_from([m.value for m in tp])
    if tp is bool:
        return st.booleans()
    if tp is int:
        lo = 0 if lo is None else lo
        return st.integers(lo, min(hi if hi is not None else lo + 100, cap if cap else 2**40))
    if tp is float or typing.get_origin(tp) is tuple:
        top = min(hi if hi is not None else 1e5, cap if cap else math.inf)
        number = st.floats(-1e5 if lo is None else lo, top, allow_nan=False, exclude_min=lo_open)
        return number if tp is float else st.lists(number, min_size=1, max_size=3)
    if tp is str:
        return st.sampled_from(["sphere", "cube", "missing.npy", "../configs/lens.npy", ""])
    return st.none()


def wrong_value() -> st.SearchStrategy:
    """Values of the wrong type or beyond any sense."""
    leaf = st.one_of(st.text(max_size=20), st.booleans(), st.integers(-10**30, 10**30),
                     st.sampled_from([math.nan, math.inf, -math.inf, 1e308, -1e308, 5e-324, -0.0]),
                     st.floats(allow_nan=True, allow_infinity=True))
    table = st.dictionaries(st.text("abcxyz_", min_size=1, max_size=6), leaf, max_size=3)
    return st.one_of(leaf, st.lists(leaf, max_size=4), table,
                     st.sampled_from(["x" * 5000, "/" * 300, "../" * 200 + "nope", "\x00bad", "ünïcødé ✓",
                                      "$(rm -rf /)", "__import__('os').system('true')"]),
                     st.integers(1, 60).map(lambda d: "[" * d + "]" * d))


def misspelt(key: str) -> st.SearchStrategy:
    return st.integers(0, len(key) - 1).map(lambda i: key[:i] + key[i + 1:] if key[i] != "." else key + "_x")


def toml_literal(value) -> str:
    """``value`` as a TOML literal for ``--set key=<literal>`` (a string that is not one is passed raw)."""
    if isinstance(value, str) and value.startswith("[") and set(value) <= {"[", "]"}:
        return value  # deep nesting, written out
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, int):
        return str(value) if abs(value) < 10**4000 else "1" * 5000
    if isinstance(value, float):
        return "nan" if math.isnan(value) else ("inf" if value > 0 else "-inf") if math.isinf(value) \
            else repr(value)
    if isinstance(value, str):
        return '"' + value.replace("\\", "\\\\").replace('"', '\\"').replace("\x00", "\\u0000") + '"'
    if isinstance(value, list):
        return "[" + ", ".join(toml_literal(v) for v in value) + "]"
    if isinstance(value, dict):
        return "{" + ", ".join(f'"{k}" = {toml_literal(v)}' for k, v in value.items()) + "}"
    return str(value)


@st.composite
def mutation(draw) -> tuple[str, str]:
    """One ``key=value`` override: a real key with a valid or a wrong value, a misspelt key, or a
    raw string."""
    leaf = draw(st.sampled_from(LEAVES))
    kind = draw(st.sampled_from(["valid", "valid", "wrong", "misspelt", "raw"]))
    if kind == "valid":
        return leaf.key, toml_literal(draw(valid_value(leaf)))
    if kind == "wrong":
        return leaf.key, toml_literal(draw(wrong_value()))
    if kind == "misspelt":
        return draw(misspelt(leaf.key)), toml_literal(draw(valid_value(leaf)))
    return leaf.key, draw(st.text(max_size=30).filter(lambda t: "\n" not in t and "\r" not in t))


def run(base: str, sets: list[tuple[str, str]], config_text: str | None = None) -> None:
    """Render through ``cli.main`` and check the property."""
    with tempfile.TemporaryDirectory() as tmp:
        config = str(CONFIGS / base)
        if config_text is not None:
            config = str(Path(tmp) / "fuzz.toml")
            Path(config).write_text(config_text, encoding="utf-8")
        out = Path(tmp) / "out"
        argv = ["render", config, "--out", str(out), "--device", "cpu", "--quiet"]
        for key, value in [(k, toml_literal(v)) for k, v in TINY.items()] + sets:
            argv += ["--set", f"{key}={value}"]
        err = io.StringIO()
        with contextlib.redirect_stderr(err), contextlib.redirect_stdout(io.StringIO()):
            code = cli.main(argv)
        lines = err.getvalue().strip().splitlines()
        event("rendered" if code == 0 else "refused")
        if code == 0:
            assert (out / "run.json").exists()
            check_outputs(out)
            return
        assert code == 2, (code, err.getvalue()[-3000:])
        assert len(lines) == 1 and lines[0].startswith("warpcaustics: error: "), err.getvalue()[-3000:]
        assert "Traceback" not in lines[0] and "Warp " not in lines[0]
        assert names_something(lines[0]), lines[0][:300]
        assert not (out / "run.json").exists()


def names_something(line: str) -> bool:
    """The message names a real key (``receivers[2].mesh`` counts as ``receivers.mesh``), a
    section, a CLI option or the config file."""
    dotted = r"[a-z_][a-z0-9_]*(?:\[\d*\])?(?:\.[a-z0-9_]+(?:\[\d*\])?)*"
    words = {re.sub(r"\[\d*\]", "", w) for w in re.findall(dotted, line)}
    return bool(words & NAMES) or any(w in line for w in CLI_WORDS)


def check_outputs(out: Path) -> None:
    """Every floor map and camera image: finite, and non-negative in its spectral channels
    (difference files exempt)."""
    import OpenEXR

    for path in out.glob("*.npz"):
        with np.load(path) as data:
            for name in ("floor_irradiance", "par_umol_m2_s"):
                assert np.all(np.isfinite(data[name])) and np.all(data[name] >= 0), (path, name)
    exrs = list(out.glob("*.exr"))
    assert exrs
    for path in exrs:
        with OpenEXR.File(str(path)) as exr:
            for name, channel in exr.channels().items():
                pixels = np.asarray(channel.pixels)
                assert np.all(np.isfinite(pixels)), (path.name, name)
                # Spectral channels are physical quantities; R, G, B are linear sRGB (or ACEScg), where
                # a saturated spectrum outside the gamut is negative by definition.
                if "_minus_" not in path.name and name.startswith("S0."):
                    assert np.all(pixels >= 0), (path.name, name)


@pytest.mark.filterwarnings("ignore")
@settings(max_examples=EXAMPLES)
@given(base=st.sampled_from(BASES), sets=st.lists(mutation(), min_size=1, max_size=3))
# issue 31's causes (each also through a subprocess in test_bad_input.py)
@example(base="ocean.toml", sets=[("optics.phase_function", '["henyey_greenstein"]')])
@example(base="ocean.toml", sets=[("output.colourspace", '["sRGB"]')])
@example(base="ocean.toml", sets=[("water.extent_m", "[" * 3000 + "]" * 3000)])
@example(base="ocean.toml", sets=[("water.model", "heightfield"), ("water.file", '"' + "x" * 5000 + '"')])
@example(base="ocean.toml", sets=[("water.extent_m", "1e30")])
@example(base="ocean.toml", sets=[("sun.elevation_deg", "1" * 100_000)])
@example(base="ocean.toml", sets=[("floor.albedo_file", '"missing.csv"')])
@example(base="ocean.toml", sets=[("sun.datetime", '"2009-07-14T11:30:00+02:00"'),
                                  ("sun.latitude_deg", "nan"), ("sun.longitude_deg", "7.3")])
# found by this fuzz: a patch of 5e-324 m divided by zero; a table key given a string; a 1e-6 m wave
# pool stepped Δt ~ 1e-9 s towards t = 0 + 1e-9 s for minutes; a file name holding a record separator;
# a CFL number of 5e-324 (a zero Δt); a 5e-324 m map window
@example(base="pool.toml", sets=[("water.extent_m", "5e-324")])
@example(base="wavepool.toml", sets=[("water.extent_m", "1e-06")])
@example(base="wavepool.toml", sets=[("water.cfl", "5e-324")])
@example(base="ocean.toml", sets=[("caustics.map_extent_m", "5e-324")])
@example(base="ocean.toml", sets=[("floor.albedo_file", '"0\x1e0"')])  # a line break to splitlines()
@example(base="ocean.toml", sets=[("stats.probes", '""')])
def test_the_cli_renders_or_names_the_key(base, sets):
    run(base, sets)


@settings(max_examples=max(20, EXAMPLES // 10))
@given(text=st.one_of(st.text(max_size=200),
                      st.integers(1, 4000).map(lambda d: "[" + ".".join(["a"] * d) + "]\nx = 1\n"),
                      st.integers(1, 4000).map(lambda d: "x = " + "{a = " * d + "1" + "}" * d + "\n"),
                      st.integers(1, 4000).map(lambda d: "x = " + "[" * d + "]" * d + "\n")))
def test_any_config_file_text_renders_or_names_the_problem(text):
    run("ocean.toml", [], config_text=text)
