"""``warpcaustics compare``: one frame of a scene by every floor-caustics method, side by side.

Each method renders the same frame (same config, time and seed; a pool is stepped to that time by
each renderer alike). Their floor maps are summed over the bands into W m⁻², normalised by their
means, and compared with the flux-ratio map (the reference: exact for a flat floor, tested
against analytic cases and against beams and exact photons): Pearson correlation and relative L1
of the normalised maps. Writes ``compare.json``, ``compare.csv``, ``compare.png`` (the methods'
previews left to right, in the order of the table) and each method's frame in ``<method>/``.
"""

from __future__ import annotations

import json
import shutil
import time
from pathlib import Path

import numpy as np

from warpcaustics.errors import WarpcausticsError

FLOOR_METHODS = ("fluxratio", "sunmap", "eikonal", "wave3d", "beams", "photons")
"""The methods that draw a floor map, reference first."""


def normalised_floor(result) -> np.ndarray:
    """Band-summed floor irradiance [W m⁻²] divided by its mean (all ones for a uniform map)."""
    total = np.einsum("kij,k->ij", result.floor_irradiance.astype(np.float64), result.bin_widths_nm)
    mean = total.mean()
    return total / mean if mean > 0 else total


def agreement(a: np.ndarray, reference: np.ndarray) -> dict[str, float]:
    """Correlation and relative L1 of two normalised maps."""
    x = a - a.mean()
    y = reference - reference.mean()
    norm = np.sqrt((x * x).sum() * (y * y).sum())
    return {"correlation": float((x * y).sum() / norm) if norm > 0 else 0.0,
            "relative_l1": float(np.abs(a - reference).sum() / max(np.abs(reference).sum(), 1e-300))}


def compare_methods(config: str | Path | None, overrides: dict, time_s: float, device: str | None,
                    methods: tuple[str, ...] = FLOOR_METHODS) -> dict:
    """Render the scene of ``config`` + ``overrides`` at ``time_s`` with each method (each variant
    validated like any config); returns ``{"rows": [...], "results": {method: RenderResult}}``,
    rows holding the correlation and relative L1 vs the flux-ratio map and the render time."""
    from warpcaustics.batch.arguments import names_argument, overrides_argument, path_argument
    from warpcaustics.pipeline import Renderer
    from warpcaustics.scene import load_scene

    if config is not None:
        config = path_argument("compare_methods", "config", config, "a scene's .toml file")
    overrides = overrides_argument("compare_methods", overrides)
    methods = names_argument("--methods", methods, FLOOR_METHODS)
    unknown = [m for m in methods if m not in FLOOR_METHODS]
    if unknown:
        raise WarpcausticsError(f"--methods: {', '.join(unknown)} is not a floor-caustics method; choose "
                                f"from {', '.join(FLOOR_METHODS)}")
    methods = ("fluxratio",) + tuple(m for m in methods if m != "fluxratio")
    scenes = {}
    for name in methods:
        try:
            scenes[name] = load_scene(config, {**overrides, "caustics.method": name})
        except WarpcausticsError as exc:
            fix = ("every comparison renders the flux-ratio reference, which needs a flat floor, no "
                   "receivers and no camera: --set floor.shape=flat --set 'receivers=[]' --set "
                   "camera.enabled=false" if name == "fluxratio" else f"drop {name!r} from --methods")
            raise WarpcausticsError(f"compare renders this scene with caustics.method = {name!r}, which it "
                                    f"cannot take: {exc} ({fix})") from None
    results = {}
    seconds = {}
    for name, scene in scenes.items():
        t0 = time.perf_counter()
        results[name] = Renderer(scene, device).render(time_s)
        seconds[name] = time.perf_counter() - t0
    reference = normalised_floor(results["fluxratio"])
    rows = []
    for name, result in results.items():
        rows.append({"method": name, **agreement(normalised_floor(result), reference),
                     "contrast": float(normalised_floor(result).std()), "render_s": seconds[name],
                     "device": result.device})
    return {"rows": rows, "results": results}


def check_compare_folder(out: Path) -> None:
    """Refuse an ``out`` that holds a render's or a sweep's results, in one line, before anything
    renders: compare would mix its files among theirs."""
    from warpcaustics.io.manifest import MANIFEST, SWEEP_FILES

    held = [name for name in (MANIFEST, "run.json", *SWEEP_FILES) if (out / name).exists()]
    if held:
        raise WarpcausticsError(f"--out {str(out)!r} holds a render's or a sweep's results ({held[0]}); "
                                "give compare a folder of its own")


def write_comparison(out: str | Path, comparison: dict, time_s: float) -> dict[str, Path]:
    """compare.json, compare.csv, compare.png and each method's frame (EXR, PNG, run.json) in
    ``out/<method>/``."""
    from warpcaustics.batch.arguments import output_folder, path_argument
    from warpcaustics.io.files import write_csv
    from warpcaustics.io.frame import save_frame
    from warpcaustics.io.png import write_png
    from warpcaustics.io.run_json import write_run_json
    from warpcaustics.optics import colour as colour_out
    from warpcaustics.pipeline import check_time

    if not (isinstance(comparison, dict) and {"rows", "results"} <= set(comparison)):
        raise WarpcausticsError(f"write_comparison() takes what compare_methods() returns; got "
                                f"{type(comparison).__name__} {comparison!r:.60}")
    check_time("time_s", time_s)
    out = output_folder("out", path_argument("write_comparison", "out", out, "the output folder"))
    for name in FLOOR_METHODS:  # an earlier comparison's method folders (each holds its run.json) go,
        folder = out / name    # so that none the new --methods leaves out stands beside its table
        if (folder / "run.json").is_file() and not folder.is_symlink():
            shutil.rmtree(folder)
    rows = comparison["rows"]
    paths = {"json": out / "compare.json", "csv": out / "compare.csv", "png": out / "compare.png"}
    images = []
    for name, result in comparison["results"].items():
        paths[name] = save_frame(result, out / name)["exr"]
        write_run_json(out / name, [result])
        xyz = colour_out.spectral_to_xyz(result.floor_irradiance[:, ::-1, :], result.bins)
        images.append(colour_out.tone_map_srgb8(colour_out.xyz_to_linear_srgb(xyz), xyz[..., 1]))
    gap = np.full((images[0].shape[0], 6, 3), 255, np.uint8)
    write_png(paths["png"], np.concatenate([x for img in images for x in (img, gap)][:-1], axis=1))
    write_csv(paths["csv"], rows)
    paths["json"].write_text(json.dumps({
        "time_s": time_s, "reference": "fluxratio",
        "note": "maps summed over bands, normalised by their means; contrast = std of the normalised map",
        "order_in_png": [r["method"] for r in rows], "rows": rows}, indent=2) + "\n")
    return paths

