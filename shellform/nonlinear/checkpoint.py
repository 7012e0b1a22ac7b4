"""Checkpoints: the last converged state in one file that any number of ranks can resume.

A driver's state (Driver.checkpoint_state) comes in three groups of local arrays:

    nodes    one row per owned carrier node (the carrier q, the contact's per-node state)
    cells    one row per owned cell (the material state at the quadrature points)
    global   the same on every rank (load factor, the holder's state, the tools' travel)

Rows are numbered globally by the mesh's input: a node by its vertex's original input index
(mesh.geometry.input_global_indices, through the cells' dofs), a cell by
mesh.topology.original_cell_index. save gathers every rank's rows to rank 0, which orders them by
these numbers and writes one .npz; read scatters them back by number to whatever ranks resume,
so that a run checkpointed on 1 rank continues on 2 and the reverse.

The file is written whole or not at all (shellform.results.tables.write_atomically), and the
previous generation is kept: CURRENT is renamed to PREVIOUS just before the new file takes
its name, so that at every moment one complete checkpoint is on disk. read takes CURRENT and,
where it is missing or damaged, PREVIOUS, and says which file was damaged and why. A write
that fails says which checkpoint is kept (kept_words), and on a full disk raises
shellform.results.disk.DiskFull.
"""

import hashlib
import json
import math
import os
import zipfile
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
from mpi4py import MPI

from shellform.errors import InputError
from shellform.results.disk import DiskFull, is_full
from shellform.results.tables import sync_folder, write_atomically

CURRENT, PREVIOUS = "checkpoint.npz", "checkpoint.previous.npz"
FORMAT = 3  # 1: last_converged.rank*.npz, one per rank; 2: without the nodes held flat
GROUPS = ("nodes", "cells", "global")


class Numbering:
    """Global numbers of the owned carrier nodes and owned cells of a mesh (see the module)."""

    def __init__(self, V, num_cells: int):
        mesh = V.mesh
        imap = V.dofmap.index_map
        n_local = imap.size_local + imap.num_ghosts
        g = mesh.geometry
        dofs, gdofs = V.dofmap.list, g.dofmaps[0]
        geometry_node = np.full(n_local, -1, dtype=np.int64)
        geometry_node[dofs] = gdofs  # a P1 carrier on a P1 geometry: the same vertex order per cell
        if dofs.shape != gdofs.shape or not np.allclose(V.tabulate_dof_coordinates()[:n_local],
                                                          g.x[geometry_node]):
            raise RuntimeError("checkpoints need a carrier with its nodes at the geometry's nodes")
        node = np.asarray(g.input_global_indices, dtype=np.int64)[geometry_node]
        self.nodes = node[: imap.size_local]
        self.cells = np.asarray(mesh.topology.original_cell_index[:num_cells], dtype=np.int64)
        self.comm = mesh.comm


def mesh_hash(V) -> str:
    """A hash of the mesh as its input numbers it: every vertex's coordinates (to 1e-10) in
    input order and every cell's vertices in original cell order; the same on any rank count."""
    mesh = V.mesh
    g, comm = mesh.geometry, mesh.comm
    owned = g.index_map().size_local
    inputs = np.asarray(g.input_global_indices, dtype=np.int64)
    num_cells = mesh.topology.index_map(mesh.topology.dim).size_local
    gdofs = g.dofmaps[0]
    pieces = comm.gather((inputs[:owned], g.x[:owned], mesh.topology.original_cell_index[:num_cells],
                          inputs[gdofs[:num_cells]]), root=0)
    digest = None
    if comm.rank == 0:
        index = np.concatenate([p[0] for p in pieces])
        x = np.concatenate([p[1] for p in pieces])[np.argsort(index)]
        cell = np.concatenate([p[2] for p in pieces])
        vertices = np.concatenate([p[3] for p in pieces])[np.argsort(cell)]
        h = hashlib.sha256(np.ascontiguousarray(np.round(x, 10)).tobytes())
        h.update(np.ascontiguousarray(vertices, dtype=np.int64).tobytes())
        digest = h.hexdigest()[:16]
    return comm.bcast(digest, root=0)


def save(folder: Path, numbering: Numbering, state: dict, meta: dict) -> Path:
    """Gather `state` (the three groups) to rank 0 and write it, with `meta` (JSON-able values,
    each stored as a JSON string), as the folder's CURRENT checkpoint; the one before becomes
    PREVIOUS. Collective; returns the path. Where the write fails (on every rank): an OSError
    saying which checkpoint is kept (the one before, or none yet), DiskFull on a full disk."""
    comm = numbering.comm
    folder = Path(folder)
    local = {"nodes": (numbering.nodes, state["nodes"]), "cells": (numbering.cells, state["cells"])}
    gathered = comm.gather({k: (idx, {n: np.asarray(a) for n, a in arrays.items()})
                            for k, (idx, arrays) in local.items()}, root=0)
    error = None
    if comm.rank == 0:
        try:
            arrays = {"format": np.array(FORMAT), **{f"meta.{k}": np.array(json.dumps(v)) for k, v in meta.items()}}
            for group in ("nodes", "cells"):
                index = np.concatenate([g[group][0] for g in gathered])
                order = np.argsort(index, kind="stable")
                arrays[f"{group}.index"] = index[order]
                for name in state[group]:
                    arrays[f"{group}.{name}"] = np.concatenate([g[group][1][name] for g in gathered])[order]
            for name, value in state["global"].items():
                arrays[f"global.{name}"] = np.asarray(value)
            folder.mkdir(parents=True, exist_ok=True)
            tmp = folder / f".{CURRENT}.new"
            write_atomically(tmp, lambda f: np.savez(f, **arrays), binary=True)
            if (folder / CURRENT).exists():
                os.replace(folder / CURRENT, folder / PREVIOUS)
            os.replace(tmp, folder / CURRENT)
            sync_folder(folder)
        except OSError as err:
            full = is_full(err)
            why = os.strerror(err.errno) if full else f"{type(err).__name__}: {err}"
            error = (full, err.errno, f"the checkpoint {folder / CURRENT} could not be written ({why})",
                     kept_words(last_complete(folder)))
    error = comm.bcast(error, root=0)
    if error is not None:
        full, code, message, kept = error
        raise DiskFull(message, code, kept) if full else OSError(f"{message}; {kept}")
    return folder / CURRENT


def last_complete(folder: Path) -> tuple[Path, dict] | None:
    """The newest checkpoint file in `folder` that opens (CURRENT, else PREVIOUS; each is written
    whole or not at all) and its global values (the load factor "lam", ...); None without one.
    Read where it is called (rank 0's view under MPI), not collective."""
    for name in (CURRENT, PREVIOUS):
        path = Path(folder) / name
        try:
            with np.load(path, allow_pickle=False) as data:
                return path, {k[len("global."):]: data[k] for k in data.files if k.startswith("global.")}
        except (OSError, ValueError, EOFError, zipfile.BadZipFile):
            continue
    return None


def kept_words(found: tuple[Path, dict] | None, at: str = "") -> str:
    """What is kept, in words: "the last complete checkpoint, PATH{at}, is kept", or that none
    was written yet (found: last_complete's answer; at: where its state lies, as " at 0.5 mm")."""
    return f"the last complete checkpoint, {found[0]}{at}, is kept" if found else "no checkpoint was written yet"


@dataclass
class Checkpoint:
    """A checkpoint as read (every rank holds all of it): its file, the files found damaged on
    the way to it, its meta values and its arrays by group (global numbering)."""
    path: Path
    meta: dict
    arrays: dict
    damaged: list = field(default_factory=list)  # "FILE: why" of each file passed over

    def local(self, numbering: Numbering) -> dict:
        """The rows of this rank's owned nodes and cells (by global number): the three groups of
        Driver.checkpoint_state."""
        out = {"global": {k[len("global."):]: v for k, v in self.arrays.items() if k.startswith("global.")}}
        for group, mine in (("nodes", numbering.nodes), ("cells", numbering.cells)):
            index = self.arrays[f"{group}.index"]
            at = np.searchsorted(index, mine)
            if index.size == 0 or np.any(at >= index.size) or np.any(index[np.minimum(at, index.size - 1)] != mine):
                raise InputError("resume", f"the checkpoint {self.path} does not fit this mesh (its {group} "
                                           "are numbered otherwise)")
            out[group] = {k[len(group) + 1:]: v[at] for k, v in self.arrays.items()
                          if k.startswith(group + ".") and k != f"{group}.index"}
        return out


def _check_sizes(path: Path, limit: float) -> None:
    """Before a member is loaded: the members' sizes (uncompressed, from the zip's directory)
    sum to at most `limit` bytes, and each member's .npy header asks for no more bytes than the
    member holds (numpy allocates the header's shape before it reads the data). ValueError."""
    with zipfile.ZipFile(path) as z:
        total = sum(info.file_size for info in z.infolist())
        if total > limit:
            raise ValueError(f"its arrays take {total / 1e6:,.1f} MB, more than the state of this run's mesh "
                             f"can ({limit / 1e6:,.1f} MB, shellform/mesh/budget.py)")
        for info in z.infolist():
            with z.open(info) as f:
                version = np.lib.format.read_magic(f)
                header = {(1, 0): np.lib.format.read_array_header_1_0,
                          (2, 0): np.lib.format.read_array_header_2_0}.get(version)
                if header is None:
                    raise ValueError(f"{info.filename} is a .npy of version {version}, which numpy's savez does not write")
                shape, _, dtype = header(f)
                need = math.prod(shape) * dtype.itemsize
            if need > info.file_size:
                raise ValueError(f"{info.filename} claims {need:,} bytes in {info.file_size:,}")


def _read_file(path: Path, limit: float = math.inf) -> tuple[dict, dict]:
    _check_sizes(path, limit)
    with np.load(path, allow_pickle=False) as data:
        arrays = {k: data[k] for k in data.files}  # reads (and CRC-checks) every member
    if int(arrays.get("format", 0)) != FORMAT:
        raise ValueError(f"format {int(arrays.get('format', 0))}, not {FORMAT}")
    for group in ("nodes", "cells"):  # every array a row per numbered node or cell (not cut)
        rows = arrays[f"{group}.index"].shape[:1] if f"{group}.index" in arrays else None
        for k, v in arrays.items():
            if k.startswith(group + ".") and (rows is None or v.shape[:1] != rows):
                raise ValueError(f"{k} has {v.shape[:1] or 'no'} rows, its index {rows or 'none'}")
    meta = {k[len("meta."):]: json.loads(str(v)) for k, v in arrays.items() if k.startswith("meta.")}
    return meta, {k: v for k, v in arrays.items() if not k.startswith("meta.") and k != "format"}


def read(folder: Path, comm=MPI.COMM_WORLD, limit: float = math.inf) -> Checkpoint:
    """The newest complete checkpoint in `folder`: CURRENT, or PREVIOUS where CURRENT is missing
    or damaged (read by rank 0, sent to every rank). InputError("resume") where there is none.
    limit: the most bytes its arrays may take (mesh.budget.state_bytes of the resuming mesh); a
    file past it counts as damaged, and nothing of it is loaded."""
    folder = Path(folder)
    found = None
    if comm.rank == 0:
        damaged = []
        for name in (CURRENT, PREVIOUS):
            path = folder / name
            if not path.exists():
                continue
            try:
                meta, arrays = _read_file(path, limit)
            except Exception as err:  # noqa: BLE001  (a damaged file: BadZipFile, EOFError, ValueError, ...)
                damaged.append(f"{path}: damaged ({type(err).__name__}: {err})")
                continue
            found = Checkpoint(path, meta, arrays, damaged)
            break
        else:
            old = sorted(folder.glob("last_converged.rank*.npz"))
            why = "; ".join(damaged) if damaged else (
                f"only {old[0].name} of an older shellform, which this one cannot read" if old else "none found")
            found = f"no usable checkpoint in {folder} ({why}): run the scene into {folder} first"
    found = comm.bcast(found, root=0)
    if isinstance(found, str):
        raise InputError("resume", found)
    return found

