"""Command line: ``warpcaustics render | study | sweep | preview | compare | report | field | config |
info``. User errors print one line and exit with 2."""

from __future__ import annotations

import argparse
import contextlib
import os
import shutil
import sys
import time
from pathlib import Path

from warpcaustics import __version__
from warpcaustics.batch.compare import FLOOR_METHODS
from warpcaustics.errors import ConfigError, WarpcausticsError

FIELD_DATASETS = ("gernez2009", "gernez2009_bands", "darecki2011", "darecki2011_wind", "darecki2011_radiance")
"""The names of ``warpcaustics.batch.field.DATASETS``, spelled here because importing that package
costs 0.7 s (scipy) at every start of the command (tests/test_field.py checks that they agree)."""

EXIT_USER_ERROR = 2

WORKERS_HELP = "worker processes (default 1; refused where that many renders at once do not fit in memory)"


def _device_arg(p: argparse.ArgumentParser, default: str = "") -> None:
    p.add_argument("--device", metavar="DEVICE", help=f"cpu, cuda, cuda:N or auto{default}")


def _set_arg(p: argparse.ArgumentParser, example: str = "") -> None:
    p.add_argument("--set", action="append", default=[], metavar="KEY=VALUE", dest="overrides",
                   help=f"override a config key{example} (repeatable)")


def _time_arg(p: argparse.ArgumentParser, what: str = "simulation time [s]") -> None:
    p.add_argument("--time", type=float, default=0.0, metavar="SECONDS", help=what)


class _Parser(argparse.ArgumentParser):
    """argparse's parser with its errors in one line, as every other bad input's (argparse prints its
    usage, up to five lines, before the error); the line points to ``--help`` for the usage."""

    def error(self, message: str):
        self.exit(EXIT_USER_ERROR, f"{self.prog}: error: {message}; see {self.prog} --help\n")


def _parser() -> argparse.ArgumentParser:
    p = _Parser(
        prog="warpcaustics",
        description="Sunlight under moving water: caustics on the sea floor with NVIDIA Warp.")
    p.add_argument("--version", action="version", version=f"warpcaustics {__version__}")
    sub = p.add_subparsers(dest="command", required=True, metavar="COMMAND")

    r = sub.add_parser("render", help="render a scene's floor caustics to EXR, PNG and run.json",
                       description="Render CONFIG (a TOML scene) into DIR: frame_NNNN.exr (RGB + "
                                   "spectral floor irradiance), frame_NNNN.png (preview), run.json.")
    r.add_argument("config", metavar="CONFIG", help="TOML scene file, e.g. configs/ocean.toml")
    r.add_argument("--out", required=True, metavar="DIR", help="output folder (created if missing)")
    _device_arg(r, " (default: $WARPCAUSTICS_DEVICE, then the config)")
    _set_arg(r, ", e.g. --set sun.elevation_deg=45")
    _time_arg(r, "simulation time of the first frame [s] (default 0)")
    r.add_argument("--frames", type=int, default=1, metavar="N", help="number of frames (default 1)")
    r.add_argument("--fps", type=float, default=30.0, metavar="F",
                   help="frames per second of an animation (default 30)")
    r.add_argument("--quiet", action="store_true", help="no progress output and no closing \"wrote …\" line")
    r.add_argument("--force", action="store_true",
                   help="write into a folder holding outputs no earlier run recorded (they are kept)")

    st = sub.add_parser("study", help="water-type study: irradiance, contrast and colour vs depth",
                        description="Render a base scene for each water type × depth × sun elevation "
                                    "of a study TOML; write study.csv, kd.csv and a plot into DIR.")
    st.add_argument("study", metavar="STUDY", help="study TOML, e.g. configs/study.toml")
    st.add_argument("--out", required=True, metavar="DIR", help="output folder")
    _device_arg(st)
    _set_arg(st, " of the study's scene")

    sw = sub.add_parser("sweep", help="run a parameter sweep (resumable) with a local process pool",
                        description="Render every scene variant × frame of a sweep TOML into "
                                    "DIR/<task id>/, skipping tasks a previous run finished; write "
                                    "DIR/manifest.jsonl and DIR/summary.csv.")
    sw.add_argument("sweep", metavar="SWEEP", help="sweep TOML, e.g. configs/sweeps/water_types.toml")
    sw.add_argument("--out", required=True, metavar="DIR", help="output folder (reused to resume)")
    sw.add_argument("--workers", type=int, default=1, metavar="N", help=WORKERS_HELP)
    sw.add_argument("--executor", default="local", choices=["local", "ray"],
                    help="local (a process pool, default) or ray (pip install 'warpcaustics[ray]')")
    sw.add_argument("--address", metavar="ADDR",
                    help="with --executor ray: an existing cluster (e.g. auto or ray://host:10001); "
                         "default: a local Ray instance of --workers CPUs")
    _device_arg(sw)
    _set_arg(sw, " for every variant (as the sweep's [set]; its [grid] and [zip] come after)")
    sw.add_argument("--quiet", action="store_true", help="no progress lines")
    sw.add_argument("--force", action="store_true", help="add this sweep to a folder holding another one")

    pv = sub.add_parser("preview", help="an off-screen 3-D view (PNG) of a scene's frame",
                        description="Render one frame of CONFIG and draw it in 3-D with pyvista: the "
                                    "floor and receivers coloured by irradiance, the water surface above.")
    pv.add_argument("config", metavar="CONFIG", help="TOML scene file")
    pv.add_argument("--out", required=True, metavar="FILE.png", help="the PNG to write")
    _time_arg(pv)
    _device_arg(pv)
    _set_arg(pv)

    cp = sub.add_parser("compare", help="one frame by every floor-caustics method, side by side",
                        description="Render one frame of CONFIG with each floor-caustics method (flux "
                                    "ratio, sun map, eikonal, wave3d, beams, photons) and compare each floor "
                                    "map with the flux-ratio map: DIR/compare.csv, compare.json, compare.png "
                                    "and each method's frame in DIR/<method>/.")
    cp.add_argument("config", metavar="CONFIG", help="TOML scene file, e.g. configs/ocean.toml")
    cp.add_argument("--out", required=True, metavar="DIR", help="output folder (created if missing)")
    cp.add_argument("--methods", default=",".join(FLOOR_METHODS), metavar="LIST",
                    help=f"comma-separated methods (default {','.join(FLOOR_METHODS)}; fluxratio, the "
                         "reference, is always included)")
    _time_arg(cp)
    _device_arg(cp)
    _set_arg(cp)

    rp = sub.add_parser("report", help="print a sweep's summary table and plot it",
                        description="Print DIR/summary.csv and write DIR/summary.png.")
    rp.add_argument("out", metavar="DIR", help="the folder of a sweep")

    _field_parser(sub)

    cf = sub.add_parser("config", help="print a scene's resolved configuration (a dry run)",
                        description="Validate CONFIG with its --set overrides and print every key with "
                                    "its value as TOML (the files it names as absolute paths, so it "
                                    "loads from any folder); nothing is rendered or written.")
    cf.add_argument("config", metavar="CONFIG", help="TOML scene file, e.g. configs/ocean.toml")
    _set_arg(cf)

    sub.add_parser("info", help="versions and the devices Warp sees",
                   description="Print package versions and the compute devices Warp can use.")
    return p


def _field_parser(sub) -> None:
    """``warpcaustics field``: a data set, its scene and each data set's own point flags."""
    fd = sub.add_parser("field", help="compare the model with field measurements (Gernez & Antoine 2009, "
                                      "Darecki et al. 2011)",
                        description="Render SCENE at the conditions of a field data set (a resumable sweep "
                                    "into DIR), and write the model against the measurements as CSV and PNG.")
    fd.add_argument("dataset", choices=list(FIELD_DATASETS), help="the field data set")
    fd.add_argument("scene", metavar="SCENE",
                    help="the scene of its conditions, e.g. configs/field/gernez2009.toml")
    fd.add_argument("--out", required=True, metavar="DIR", help="output folder (reused to resume)")
    fd.add_argument("--series", metavar="S",
                    help="gernez2009: comma-separated of zenith, wind (CV vs √wind), overcast, water (CV vs "
                         "Kd(490), the Jerlov types); default zenith,wind")
    fd.add_argument("--zeniths", metavar="LIST",
                    help="gernez2009(_bands): only these measured sun zeniths [deg], comma-separated "
                         "(default all)")
    fd.add_argument("--sqrt-winds", metavar="LIST",
                    help="gernez2009: only these measured √wind classes [√(m/s)], comma-separated")
    fd.add_argument("--depths", metavar="LIST",
                    help="darecki2011: these depths [m], comma-separated (default the measured ones; others "
                         "give the model's CV(z) with no measurement beside it)")
    fd.add_argument("--winds", metavar="LIST",
                    help="darecki2011_wind: only these measured winds [m/s], comma-separated (default all)")
    fd.add_argument("--panels", metavar="LIST",
                    help="darecki2011_radiance: only these of Fig. 15's panels, comma-separated "
                         "(default a,b,c)")
    fd.add_argument("--view-zeniths", metavar="LIST",
                    help="darecki2011_radiance: only these of the record's sensor zeniths [deg] (+: towards "
                         "the sun), comma-separated (default those inside Snell's window, -30 to 40)")
    fd.add_argument("--long-waves", type=float, metavar="M",
                    help="gernez2009(_bands), darecki2011: side [m] of a patch of the waves longer than the "
                         "scene's, rendered too (default 128 and 0); 0: the scene's waves alone")
    fd.add_argument("--frames", type=int, metavar="N",
                    help="frames pooled per point (default 3; darecki2011_radiance 2)")
    fd.add_argument("--frame-interval", type=float, metavar="S",
                    help="seconds between a point's frames (default: gernez2009(_bands) 2, the darecki2011 "
                         "data sets 5); "
                         "frames further apart than the waves' periods are independent samples")
    fd.add_argument("--workers", type=int, default=1, metavar="N", help=WORKERS_HELP)
    _device_arg(fd)
    _set_arg(fd, ", on every point (a row of the error budget)")
    fd.add_argument("--quick", action="store_true",
                    help="a coarse run of two or three points, to check the command (not a comparison)")
    fd.add_argument("--quiet", action="store_true", help="no progress lines")
    fd.add_argument("--force", action="store_true", help="add this run to a folder holding another one")


def _overrides(args: argparse.Namespace) -> dict:
    from warpcaustics.config import parse_override

    return dict(parse_override(text) for text in args.overrides)


def _floats(text: str | None, flag: str) -> tuple[float, ...] | None:
    """A comma-separated list of numbers, or None when the flag was not given."""
    if text is None:
        return None
    try:
        return tuple(float(x) for x in text.split(","))
    except ValueError:
        raise ConfigError(f"{flag} {text!r} must be comma-separated numbers, e.g. {flag} 1,2.5") from None


def _field(args: argparse.Namespace) -> int:
    """``warpcaustics field``: each data set takes its own point flags; another's is an error."""
    from warpcaustics.batch.field import DATASETS, LONG_WAVES_DATASETS, POINT_FLAGS

    own = POINT_FLAGS[args.dataset]
    for name in sorted({flag for flags in POINT_FLAGS.values() for flag in flags}):
        if name not in own and getattr(args, name) is not None:
            raise ConfigError(f"--{name.replace('_', '-')} is not a flag of {args.dataset} "
                              f"(its point flags: {', '.join('--' + n.replace('_', '-') for n in own)})")
    points = {}
    for name in own:
        text = getattr(args, name)
        if text is not None:  # else the data set's own default: all its points
            flag = "--" + name.replace("_", "-")
            points[name] = tuple(text.split(",")) if name in ("series", "panels") else _floats(text, flag)
    common = dict(workers=args.workers, device=args.device, quick=args.quick,
                  quiet=args.quiet, force=args.force, overrides=_overrides(args))
    if args.frames is not None:  # else each data set's own default
        common["frames"] = args.frames
    if args.frame_interval is not None:
        common["frame_interval_s"] = args.frame_interval
    if args.long_waves is not None:
        if args.dataset not in LONG_WAVES_DATASETS:
            raise ConfigError(f"--long-waves is a flag of {', '.join(LONG_WAVES_DATASETS)}, not of "
                              f"{args.dataset}")
        common["long_waves_m"] = args.long_waves
    paths = DATASETS[args.dataset](args.scene, args.out, **points, **common)
    print("wrote " + ", ".join(str(p) for p in paths.values()))
    return 0


def _out_folder(text: str) -> Path:
    """--out as a folder: refused at once if it is empty, a file, or a folder that cannot be written
    (read-only, no permission), before anything renders."""
    if not text.strip():
        raise ConfigError("--out is empty; give a folder, e.g. --out out/run")
    out = Path(text)
    if out.exists() and not out.is_dir():
        raise WarpcausticsError(f"--out {text!r} is a file; give a folder")
    if out.is_dir():
        _writable(out / f".warpcaustics-probe-{os.getpid()}", text)
    return out


def _writable(probe: Path, out: str) -> None:
    """Create and remove the file ``probe``; one line naming ``--out`` if it cannot be."""
    try:
        probe.open("xb").close()
        probe.unlink()
    except OSError as exc:
        raise WarpcausticsError(f"--out {out!r} cannot be written: {exc.strerror or exc}; "
                                "give a folder you can write to") from None


def _make(out: Path) -> Path | None:
    """Make the folder ``out`` (one line if it cannot be made); the first folder this made (None: it
    was there), which a command that fails removes."""
    from warpcaustics.batch.arguments import output_folder

    made = next((f for f in reversed([out, *out.parents]) if not f.exists()), None)
    output_folder("--out", out)
    return made


@contextlib.contextmanager
def _made_out(out: Path):
    """Make ``out`` now, before anything renders, and remove what this made if the command fails
    before it is done: no folder left behind as if it were a result."""
    made = _make(out)
    try:
        yield out
    except BaseException:
        if made is not None:
            shutil.rmtree(made, ignore_errors=True)
        raise


def _config(args: argparse.Namespace) -> int:
    """The resolved configuration as TOML (every key with its value): load_scene's whole validation,
    the files it names included, and nothing rendered."""
    from warpcaustics.config import config_to_dict
    from warpcaustics.io.toml_out import dumps_toml
    from warpcaustics.scene import load_scene

    scene = load_scene(args.config, _overrides(args))
    print(dumps_toml(_absolute_files(config_to_dict(scene.config), scene.base_dir)), end="")
    return 0


def _absolute_files(table, base_dir: Path):
    """``table`` with the files its keys name (``file``, ``albedo_file``, a receiver's ``mesh`` that
    is no built-in shape) as absolute paths: a relative one starts at the config file's folder, so
    the printed config loads from anywhere."""
    from warpcaustics.scene import is_file_key

    if isinstance(table, list):
        return [_absolute_files(item, base_dir) for item in table]
    if not isinstance(table, dict):
        return table
    return {key: str(base_dir / value) if is_file_key(key, value) else _absolute_files(value, base_dir)
            for key, value in table.items()}


def _render(args: argparse.Namespace) -> int:
    from warpcaustics.scene import load_scene

    overrides = _overrides(args)
    scene = load_scene(args.config, overrides)  # validate everything before touching the output
    _check_animation(args, scene.config.stats.integration_s)
    out = _out_folder(args.out)

    from warpcaustics.io.files import folder_lock
    from warpcaustics.io.frame import save_frame
    from warpcaustics.io.run_json import write_run_json
    from warpcaustics.pipeline import Renderer

    renderer = Renderer(scene, args.device)  # device and memory checks before any output
    made = _make(out)
    with folder_lock(out):  # a second run into the same folder is refused, not interleaved
        results = []
        from warpcaustics.batch.progress import Progress
        from warpcaustics.io.manifest import claim

        manifest = claim(out, args.force)  # the earlier run's files go; unrecorded outputs are refused
        # run.json marks a complete run: an earlier run's must not stand beside this run's frames
        (out / "run.json").unlink(missing_ok=True)
        progress = Progress(args.frames, args.quiet, unit="frame")
        try:
            for frame in range(args.frames):
                t0 = time.perf_counter()
                result = renderer.render(args.time + frame / args.fps)
                try:
                    with renderer.memory_errors():
                        manifest.add(save_frame(result, out, frame=frame).values())
                except OSError as exc:
                    raise WarpcausticsError(f"cannot write frame {frame} into --out {str(out)!r}: "
                                            f"{exc.strerror or exc}") from None
                results.append(result)
                progress.step(f"frame {frame:04d}  t = {result.time_s:.3f} s  "
                              f"{time.perf_counter() - t0:.2f} s  on {result.device}  -> "
                              f"{out / f'frame_{frame:04d}.exr'}")
        except BaseException:
            if made is not None and not results:  # failed before its first frame: what this run made goes
                shutil.rmtree(made, ignore_errors=True)
            raise
        finally:
            progress.close()
        write_run_json(out, results)
        manifest.add([out / "run.json"])
        if not args.quiet:
            print(f"wrote {args.frames} frame(s) and run.json to {out}")
        return 0


def _study(args: argparse.Namespace) -> int:
    from warpcaustics.batch.study import load_study, run_study

    study = load_study(args.study, _overrides(args))
    out = _out_folder(args.out)
    t0 = time.perf_counter()
    with _made_out(out):
        paths = run_study(study, out, device=args.device)
    count = len(study.water_types) * len(study.depths_m) * len(study.sun_elevations_deg)
    print(f"{count} renders in {time.perf_counter() - t0:.1f} s; wrote "
          + ", ".join(str(p) for p in paths.values()))
    return 0


def _preview(args: argparse.Namespace) -> int:
    from warpcaustics.io.preview import preview_png
    from warpcaustics.pipeline import render
    from warpcaustics.scene import load_scene

    out = Path(args.out)
    if out.suffix.lower() != ".png":
        raise WarpcausticsError(f"--out {str(out)!r} must name a .png file")
    scene = load_scene(args.config, _overrides(args))
    if not out.parent.is_dir():
        raise WarpcausticsError(f"--out {str(out)!r}: the folder {str(out.parent)!r} does not exist")
    if out.is_dir():
        raise WarpcausticsError(f"--out {str(out)!r} is a folder; name the .png file to write")
    # a folder the PNG cannot be written into fails now, not as pyvista's error after the render
    _writable(out.with_name(f".{out.stem}.probe-{os.getpid()}"), str(out))
    from warpcaustics.pipeline import check_time

    check_time("--time", args.time)
    preview_png(render(scene, args.time, args.device), out)
    print(f"wrote {out}")
    return 0


def _check_animation(args: argparse.Namespace, integration_s: float) -> None:
    """The render command's --frames, --fps and --time, and whether an animation that long holds the
    radiometer's integration (``stats.integration_s``) it is asked to report: before any output."""
    from warpcaustics.io.run_json import integration_frames
    from warpcaustics.pipeline import check_time

    if args.frames < 1:
        raise WarpcausticsError(f"--frames = {args.frames} must be at least 1")
    if not args.fps > 0 or args.fps == float("inf"):
        raise WarpcausticsError(f"--fps = {args.fps} must be a positive number")
    check_time("--time", args.time)
    check_time("--time + (--frames - 1) / --fps", args.time + (args.frames - 1) / args.fps)
    needed = integration_frames(integration_s, 1 / args.fps)
    if args.frames >= 3 and integration_s > 0 and args.frames < needed:  # three frames: time statistics
        raise WarpcausticsError(
            f"stats.integration_s = {integration_s:g} needs --frames ≥ {needed} at --fps {args.fps:g} for "
            "its time statistics (three samples after the first whole window); give more frames or a "
            "shorter integration_s")


def _compare(args: argparse.Namespace) -> int:
    from warpcaustics.batch.compare import check_compare_folder, compare_methods, write_comparison
    from warpcaustics.pipeline import check_time

    check_time("--time", args.time)
    out = _out_folder(args.out)
    if out.is_dir():
        check_compare_folder(out)
    methods = tuple(m.strip() for m in args.methods.split(",") if m.strip())
    if not methods:
        raise ConfigError(f"--methods {args.methods!r} names no method; give some of "
                          f"{', '.join(FLOOR_METHODS)}, e.g. --methods photons,beams")
    overrides = _overrides(args)
    with _made_out(out):
        comparison = compare_methods(args.config, overrides, args.time, args.device, methods)
        paths = write_comparison(out, comparison, args.time)
    print(f"{'method':10s} {'correlation':>11s} {'rel. L1':>8s} {'contrast':>8s} {'seconds':>8s}"
          "   (normalised maps vs fluxratio)")
    for r in comparison["rows"]:
        print(f"{r['method']:10s} {r['correlation']:11.3f} {r['relative_l1']:8.3f} {r['contrast']:8.3f} "
              f"{r['render_s']:8.2f}")
    print(f"wrote {paths['csv']}, {paths['json']}, {paths['png']}")
    return 0


def extras() -> dict[str, list[str]]:
    """Each optional extra of the installed package with the distributions it lacks ([] when installed)."""
    import re
    from importlib import metadata

    out: dict[str, list[str]] = {}
    for requirement in metadata.requires("warpcaustics") or []:
        marker = re.search(r"""extra\s*==\s*["']([^"']+)["']""", requirement)
        if not marker:
            continue
        name = re.match(r"[A-Za-z0-9_.-]+", requirement).group(0)
        missing = out.setdefault(marker.group(1), [])
        try:
            metadata.version(name)
        except metadata.PackageNotFoundError:
            missing.append(name)
    return out


def _info() -> int:
    from warpcaustics.device import DEVICE_ENV
    from warpcaustics.io.files import versions

    for name, version in versions().items():
        print(f"{name:16s}{version}")
    print("extras:")
    for extra, missing in extras().items():
        fix = f"missing {', '.join(missing)}: pip install 'warpcaustics[{extra}]'"
        print(f"  {extra:14s}{fix if missing else 'installed'}")
    import os

    from warpcaustics.device import _warp

    wp = _warp()
    print("devices:")
    for d in wp.get_devices():
        extra = f"  {d.total_memory / 1024**3:.1f} GiB" if d.is_cuda else ""
        print(f"  {d.alias:8s}{d.name}{extra}")
    from warpcaustics.device import resolve_device

    try:  # what a render without --device would take: $WARPCAUSTICS_DEVICE first, as a render reads it
        default = resolve_device(None)
    except WarpcausticsError as exc:
        default = f"none: {exc}"
    print(f"default device: {default}  (override: --device or ${DEVICE_ENV}="
          f"{os.environ.get(DEVICE_ENV, '')})")
    return 0


def one_line(text: str) -> str:
    """A message as one printable line: control characters (a newline, or a record separator that
    a file name given in a config carried) written as escapes."""
    return "".join(c if c.isprintable() else repr(c)[1:-1] for c in text)


SIGNED_LIST_FLAGS = ("--view-zeniths",)
"""Flags whose list may start with a negative number, which argparse would take for a flag."""


def _signed_lists(argv: list[str]) -> list[str]:
    """``--view-zeniths -30,0`` as ``--view-zeniths=-30,0``, so that argparse takes the list."""
    out = []
    for arg in argv:
        if out and out[-1] in SIGNED_LIST_FLAGS and arg[:1] == "-" and arg[1:2].isdigit():
            out[-1] = f"{out[-1]}={arg}"
        else:
            out.append(arg)
    return out


def _os_error_line(exc: OSError, out: str | None) -> str:
    """The file that failed and why; the advice about --out only where the file is in it (a full disk
    there), not for a file elsewhere (too many open files, no temporary folder)."""
    where = f"{str(exc.filename)!r}: " if exc.filename else ""
    line = one_line(where + (exc.strerror or str(exc)))
    try:
        failed = Path(os.fsdecode(exc.filename)).resolve() if exc.filename and out else None
        inside = failed is not None and Path(out).resolve() in failed.parents
    except (OSError, ValueError, TypeError):
        inside = False
    if inside:
        return (f"{line}; free space in --out or give another --out (what was written is not marked a "
                "finished run)")
    return line


def main(argv: list[str] | None = None) -> int:
    for name in ("stdout", "stderr"):  # started with the stream closed (`>&-`): what it says goes nowhere
        if getattr(sys, name) is None:
            setattr(sys, name, open(os.devnull, "w", encoding="utf-8"))
    args = _parser().parse_args(_signed_lists(sys.argv[1:] if argv is None else list(argv)))
    try:
        if args.command in ("sweep", "field"):  # render, study and compare check theirs as they use it
            _out_folder(args.out)  # an empty --out would write into the working folder
        if args.command == "render":
            return _render(args)
        if args.command == "study":
            return _study(args)
        if args.command == "sweep":
            from warpcaustics.batch.sweep import sweep_main

            if args.address is not None and args.executor != "ray":
                raise ConfigError(f"--address {args.address!r} is the Ray cluster to run on; add "
                                  "--executor ray (or leave --address out)")

            return sweep_main(args.sweep, args.out, args.workers, args.device, args.quiet, args.executor,
                              args.address, _overrides(args), args.force)
        if args.command == "config":
            return _config(args)
        if args.command == "preview":
            return _preview(args)
        if args.command == "compare":
            return _compare(args)
        if args.command == "field":
            return _field(args)
        if args.command == "report":
            from warpcaustics.batch.report import report_main

            return report_main(args.out)
        return _info()
    except WarpcausticsError as exc:
        print(f"warpcaustics: error: {one_line(str(exc))}", file=sys.stderr)
        return EXIT_USER_ERROR
    except BrokenPipeError:  # what it printed was piped to a reader that stopped (`| head -1`): not an error
        from warpcaustics.batch.progress import stdout_to_devnull

        stdout_to_devnull()
        return 0
    except OSError as exc:  # a file that failed as it went (a disk that filled): which, and why
        print(f"warpcaustics: error: {_os_error_line(exc, getattr(args, 'out', None))}", file=sys.stderr)
        return EXIT_USER_ERROR
    except KeyboardInterrupt:
        print("warpcaustics: interrupted", file=sys.stderr)
        return 130


if __name__ == "__main__":
    sys.exit(main())
