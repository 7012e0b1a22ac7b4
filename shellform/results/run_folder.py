"""The output folder of a run (--out): checked before any computation, and owned by one run.

check_writable   the folder is created (with its parents) and proven writable by creating and
                 removing a probe file, on every rank; else InputError("--out").
start            run.json, the manifest of the run in the folder: the scene file, the scene's
                 hash, its title, the code version, when it started (and when it was resumed).
                 A run without --resume starts afresh: it removes the files a shellform run
                 writes there (OUTPUTS: summaries, tables, pictures, fields, checkpoints), so that
                 nothing of an older run is mixed with its own, and it refuses a folder that
                 holds another scene's run (another scene file and another content), naming that
                 run's title and scene file. A link with an output's name is removed first, by a
                 fresh run and a resume alike (remove_links): never read or written through.
fingerprint      what defines a run's state (scene content but for the knobs of how to continue,
                 the files it reads, the code version, the mesh), and how it continues.
"""

import hashlib
import importlib.util
import json
import os
import shutil
import time
from dataclasses import asdict
from fnmatch import fnmatch
from functools import lru_cache
from pathlib import Path

from mpi4py import MPI

import shellform
from shellform.errors import InputError
from shellform.results.disk import DiskFull
from shellform.results.tables import write_json

MANIFEST = "run.json"
# what shellform's runs write into --out (shellform/run.py's routes: results/shell.py, nonlinear/run.py, contact/run.py)
OUTPUTS = ("summary.json", "reports.json", "history.json", "increments.csv", "force_stroke.csv",
           "force_stroke.png", "thickness_*.csv", "thickness.png", "fld.csv", "fld.png", "strain_path.csv", "rim.csv",
           "rim.png", "cup.png", "cup_margin.png",
           "springback.csv", "springback.png", "deformed.png", "cup.bp", "cup_cells.bp",
           "cup.pvd", "sheet.pvd", "punch.pvd", "die.pvd", "blank_holder.pvd", "vtu", "nodal.bp", "cells.bp", "checkpoint.npz",
           "checkpoint.previous.npz", ".checkpoint.npz.new", "last_converged.rank*.npz")
# what may change when a run is resumed ("how to continue"; `shellform run --resume`)
CONTINUE = ("title", "tools.stroke", "tools.friction", "tools.punch_friction", "tools.die_friction",
            "tools.holder_friction", "tools.blank_holder_force", "effects.friction",
            "process.initial_step", "process.min_step", "process.max_step", "process.initial_step_mm",
            "process.min_step_mm", "process.max_step_mm", "process.max_iterations",
            "process.rtol", "process.path", "process.report", "process.springback", "process.stop_at_forming_limit",
            "process.stop_at_neck", "output.vtx", "output.vtu", "output.png", "output.fld", "output.checkpoint_every")
# of those, the process inputs that act on the sheet from its first increment: a resume may
# change them only from a checkpoint before any increment; past it, a run with other ones is
# another run (refused, naming them)
PROCESS = ("tools.blank_holder_force", "tools.friction", "tools.punch_friction", "tools.die_friction",
           "tools.holder_friction", "effects.friction")


def check_writable(outdir: Path, comm=MPI.COMM_WORLD) -> None:
    """Create outdir and prove it writable (a probe file created and removed) on every rank;
    InputError("--out") naming the cause on all ranks where any fails."""
    outdir = Path(outdir)
    error = None
    if outdir.exists() and not outdir.is_dir():
        error = f"{outdir} is a file, not a folder"
    else:
        try:
            outdir.mkdir(parents=True, exist_ok=True)
            probe = outdir / f".shellform-probe.{os.getpid()}.rank{comm.rank}"
            with open(probe, "w") as f:
                f.write("probe\n")
                f.flush()
                os.fsync(f.fileno())
            probe.unlink()
        except OSError as err:
            error = f"cannot write into {outdir} ({err.strerror or type(err).__name__})"
    errors = [e for e in comm.allgather(error) if e]
    if errors:
        raise InputError("--out", errors[0])


def _file_digest(path: str) -> str:
    try:
        return hashlib.sha256(Path(path).read_bytes()).hexdigest()[:16]
    except OSError:
        return "unreadable"


def scene_record(s) -> dict:
    """The validated scene as flat fields ("tools.stroke": 30.0), each file it reads by its
    content's hash; "effects" without friction and "effects.friction" on its own."""
    flat = {}

    def walk(prefix, value):
        if isinstance(value, dict) and prefix.split(".")[0] != "supports":
            for k, v in value.items():
                walk(f"{prefix}.{k}" if prefix else k, v)
        else:
            flat[prefix] = value

    data = asdict(s)
    walk("", data)
    if flat.get("geometry.file"):
        flat["geometry.file"] = {"name": Path(flat["geometry.file"]).name,
                                 "sha256": _file_digest(flat["geometry.file"])}
    effects = list(s.effects)
    flat["effects"] = sorted(e for e in effects if e != "friction")
    flat["effects.friction"] = "friction" in effects
    return json.loads(json.dumps(flat, default=str))


def scene_hash(s) -> str:
    return hashlib.sha256(json.dumps(scene_record(s), sort_keys=True).encode()).hexdigest()[:16]


@lru_cache(maxsize=1)
def code_version() -> str:
    """shellform's version and a hash of its sources (the package and its forms): any change of
    the code gives another version. Each folder is the one the import system finds (a wheel holds
    forms/ inside the package, the clone beside it), never a guess beside the package (in a wheel
    that is site-packages); the demos (shellform.demos: scenes and literate scripts) are data, not
    code, and left out, so that the same code has the same version in every kind of install."""
    root = Path(shellform.__file__).resolve().parent
    forms = Path(importlib.util.find_spec("shellform.forms").origin).resolve().parent
    inside = [root / "forms", root / "demos"]  # a wheel's; hashed as their own folder, or not at all
    h = hashlib.sha256()
    for folder in (root, forms):
        for f in sorted(folder.rglob("*.py")):
            if folder == root and any(f.is_relative_to(d) for d in inside):
                continue
            h.update(str(f.relative_to(folder)).encode())
            h.update(f.read_bytes())
    return f"{shellform.__version__}+src.{h.hexdigest()[:12]}"


def fingerprint(s, mesh: str) -> dict:
    """What defines a run and its checkpoint: "state" (the scene's fields but CONTINUE, the code
    version, the mesh's hash), which a resume must match, and "continue" (CONTINUE's fields),
    which may differ."""
    record = scene_record(s)
    return {"state": {**{k: v for k, v in record.items() if k not in CONTINUE},
                      "code_version": code_version(), "mesh": mesh},
            "continue": {k: record[k] for k in CONTINUE if k in record}}


def compare(saved: dict, now: dict) -> tuple[list[str], dict]:
    """(the state fields that differ, {continue field: {"checkpoint": old, "now": new}})."""
    old, new = saved.get("state", {}), now["state"]
    differ = sorted(k for k in set(old) | set(new) if old.get(k) != new.get(k))
    before, after = saved.get("continue", {}), now["continue"]
    changed = {k: {"checkpoint": before.get(k), "now": after.get(k)} for k in sorted(set(before) | set(after))
               if before.get(k) != after.get(k)}
    return differ, changed


def check_process(changed: dict, at_mm: float, path) -> None:
    """Refuse a resume from a checkpoint at at_mm > 0 whose process inputs (PROCESS) differ
    from this scene's (changed: compare's second value): InputError naming the first of them,
    and every one with its value in the checkpoint and now."""
    fields = [k for k in PROCESS if k in changed]
    if not fields or at_mm <= 0.0:
        return
    values = ", ".join(f"{k} {changed[k]['checkpoint']!r} there, {changed[k]['now']!r} now" for k in fields)
    raise InputError(fields[0], f"the checkpoint {path} at {at_mm:.6g} mm was drawn with other process inputs "
                                f"({values}); they act from the first increment, so this is another run: run it "
                                "into another folder (without --resume)")


def read_manifest(outdir: Path) -> dict | None:
    try:
        return json.loads((Path(outdir) / MANIFEST).read_text())
    except (OSError, ValueError):
        return None


def start(outdir: Path, s, scene_path=None, resume: bool = False, comm=MPI.COMM_WORLD) -> dict | None:
    """Check outdir (check_writable), and make it this run's: without resume, refuse another
    scene's run or clear the older run's outputs, and write run.json (returned). With resume
    nothing changes yet: the resume's checks come first, then resumed() updates run.json.
    DiskFull on every rank where run.json finds no room."""
    outdir = Path(outdir)
    check_writable(outdir, comm)
    if comm.rank == 0:
        remove_links(outdir)
    comm.barrier()
    if resume:
        return None
    scene_path = str(Path(scene_path).resolve()) if scene_path else None
    digest = scene_hash(s)
    error, full, manifest = None, None, None
    if comm.rank == 0:
        old = read_manifest(outdir)
        if old and old.get("scene") and scene_path and old["scene"] != scene_path \
                and old.get("scene_hash") != digest:
            error = (f"{outdir} holds the run of another scene, {old.get('title')!r} ({old['scene']}): "
                     "choose another folder, or remove that run first")
        else:
            now = time.strftime("%Y-%m-%dT%H:%M:%S%z")
            manifest = {"scene": scene_path, "scene_hash": digest, "title": s.title,
                        "code_version": code_version(), "started": now, "resumed": []}
            clear(outdir)
            try:
                write_json(outdir / MANIFEST, manifest)
            except DiskFull as err:  # on every rank, below
                full = (err.strerror, err.errno)
    error, full, manifest = comm.bcast((error, full, manifest), root=0)
    if error:
        raise InputError("--out", error)
    if full:
        raise DiskFull(*full)
    return manifest


def resumed(outdir: Path, s, scene_path=None, comm=MPI.COMM_WORLD) -> None:
    """run.json after a resume's checks passed: this scene, the run's start, and the resume's
    time appended to "resumed"."""
    if comm.rank == 0:
        old = read_manifest(outdir) or {}
        now = time.strftime("%Y-%m-%dT%H:%M:%S%z")
        write_json(Path(outdir) / MANIFEST, {
            "scene": str(Path(scene_path).resolve()) if scene_path else None, "scene_hash": scene_hash(s),
            "title": s.title, "code_version": code_version(), "started": old.get("started", now),
            "resumed": old.get("resumed", []) + [now]})


def remove_links(outdir: Path) -> None:
    """Remove every link in outdir with the name of an output (OUTPUTS, to a file or a folder
    anywhere) and every link inside the output folders (vtu/, the .bp series): what a run
    reads and writes there is its own, never what a link points to."""
    outdir = Path(outdir)
    for pattern in OUTPUTS:
        for f in outdir.glob(pattern):
            if f.is_symlink():
                f.unlink(missing_ok=True)
            elif f.is_dir():
                for folder, dirs, files in os.walk(f):  # links to folders are listed, not followed
                    for name in dirs + files:
                        if os.path.islink(os.path.join(folder, name)):
                            os.unlink(os.path.join(folder, name))


def clear(outdir: Path) -> None:
    """Remove what a shellform run writes (OUTPUTS, and the temporary files of writes that a
    kill interrupted: .NAME.PID.tmp) from outdir; nothing else."""
    outdir = Path(outdir)
    for f in outdir.glob(".*.*.tmp"):
        name = f.name[1:].rsplit(".", 2)[0]
        if any(fnmatch(name, pattern) for pattern in OUTPUTS):
            f.unlink(missing_ok=True)
    for pattern in OUTPUTS:
        for f in outdir.glob(pattern):
            if f.is_dir() and not f.is_symlink():
                shutil.rmtree(f, ignore_errors=True)
            else:  # a file, or a link (to a folder too: the run must not write through it)
                f.unlink(missing_ok=True)
