"""A render owns its output folder through a manifest, ``DIR/outputs.json``: the files the run wrote,
kept current frame by frame. A new run into the folder first removes the files the earlier run's
manifest lists (so no ``.nc``, ``.npz`` or ``.vti`` of other settings stays beside the new frames),
and refuses, unless ``--force``, outputs it finds without a manifest. It never deletes a file that
no manifest lists."""

from __future__ import annotations

import json
from pathlib import Path

from warpcaustics import __version__
from warpcaustics.errors import WarpcausticsError
from warpcaustics.io.files import atomic_path

MANIFEST = "outputs.json"
SWEEP_MANIFEST = "manifest.jsonl"
"""A sweep's record of its tasks, one JSON line each (``batch/sweep.py``)."""
SWEEP_RECORD = "sweep.json"
"""Which sweep a folder holds: the hash of its task ids (the resolved configs, times and version)."""
SWEEP_FILES = (SWEEP_MANIFEST, SWEEP_RECORD)
"""What a sweep (``batch/sweep.py``, the field commands) keeps in its folder: a render refuses to
write among them without --force."""

OUTPUT_GLOBS = ("frame_[0-9]*", "camera_[0-9]*", "surface_[0-9]*", "floor_[0-9]*", "receivers_[0-9]*",
                "run.json")
"""Names a render writes (docs/architecture.md's outputs table): what an unowned folder is checked for."""


class RunManifest:
    """The files one render wrote into ``out`` (names relative to it)."""

    def __init__(self, out: Path):
        self.out = out
        self.files: list[str] = []

    def add(self, paths) -> None:
        """Record written files and rewrite the manifest (atomically), so a run that fails later
        still lists everything it left."""
        for path in paths:
            name = Path(path).resolve().relative_to(self.out.resolve()).as_posix()
            if name not in self.files:
                self.files.append(name)
        with atomic_path(self.out / MANIFEST) as tmp:
            tmp.write_text(json.dumps({"version": __version__, "files": self.files}, indent=1) + "\n",
                           encoding="utf-8")


def claim(out: Path, force: bool) -> RunManifest:
    """Take ``out`` for a new run: remove what the earlier run's manifest lists, or, where outputs
    stand without a manifest, refuse (a one-line error naming ``--force``) unless ``force``."""
    manifest = out / MANIFEST
    if not force and any((out / name).exists() for name in SWEEP_FILES):
        raise WarpcausticsError(f"--out {str(out)!r} holds a sweep's results (manifest.jsonl, sweep.json); "
                                "give another --out, or --force to write beside them")
    if manifest.exists():
        try:
            listed = json.loads(manifest.read_text(encoding="utf-8"))["files"]
            if not isinstance(listed, list) or not all(isinstance(n, str) and "\0" not in n for n in listed):
                raise TypeError("not a list of file names")
        except (OSError, ValueError, KeyError, TypeError):
            raise WarpcausticsError(f"--out {str(out)!r}: its {MANIFEST} cannot be read; remove the folder's "
                                    "outputs by hand or give another --out") from None
        for name in listed:
            path = out / name
            if path.resolve().parent == out.resolve() and path.is_file():
                path.unlink()
        manifest.unlink()
    elif not force:
        found = sorted({p.name for pattern in OUTPUT_GLOBS for p in out.glob(pattern)})
        if found:
            raise WarpcausticsError(f"--out {str(out)!r} holds outputs no run of this version recorded "
                                    f"({', '.join(found[:3])}{', …' if len(found) > 3 else ''}); give "
                                    "another --out, or --force to write beside them")
    return RunManifest(out)
