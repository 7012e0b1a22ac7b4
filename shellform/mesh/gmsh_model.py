"""gmsh on rank 0, the mesh on every rank: the one path by which shellform builds or reads an
unstructured mesh (rectangle, circle, polygon, a user's .geo or .msh file).

``mesh_on_root(comm, build, what)`` runs ``build(gmsh)`` on rank 0 in a fresh gmsh model with
shellform's options, then hands the model to DOLFINx, which distributes it. An error on rank 0
is raised on every rank (as RuntimeError, or the InputError that build raised), so no rank hangs.
"""

from contextlib import contextmanager

import dolfinx.mesh
from shellform.errors import InputError

OPTIONS = {
    "General.Terminal": 0,
    "General.Verbosity": 0,
    "General.NumThreads": 1,
    "Mesh.Algorithm": 6,  # Frontal-Delaunay
    "Mesh.RandomSeed": 1,
    "Mesh.ElementOrder": 1,
    "Mesh.RecombineAll": 0,
    "Mesh.MeshSizeFromCurvature": 0,
    "Mesh.MeshSizeExtendFromBoundary": 1,
    "Mesh.MeshSizeFromPoints": 1,
    "Mesh.MeshSizeMin": 0.0,
}


def partitioner():
    return dolfinx.mesh.create_cell_partitioner(dolfinx.mesh.GhostMode.shared_facet, 2)


@contextmanager
def gmsh_session():
    """A fresh gmsh model with shellform's options; restores gmsh's previous state afterwards."""
    import gmsh

    owner = not gmsh.isInitialized()
    if owner:
        gmsh.initialize(readConfigFiles=False, interruptible=False)
    saved = {k: gmsh.option.getNumber(k) for k in (*OPTIONS, "Mesh.MeshSizeMax")}
    previous = gmsh.model.getCurrent() if not owner else None
    try:
        for k, v in OPTIONS.items():
            gmsh.option.setNumber(k, v)
        gmsh.model.add("shellform_blank")
        yield gmsh
    finally:
        if owner:
            gmsh.finalize()
        else:
            gmsh.model.remove()
            if previous:
                gmsh.model.setCurrent(previous)
            for k, v in saved.items():
                gmsh.option.setNumber(k, v)


@contextmanager
def _nothing():
    yield None


def mesh_on_root(comm, build, what: str, root: int = 0):
    """DOLFINx MeshData (mesh, facet_tags, physical_groups) of the gmsh model that build(gmsh)
    makes on rank `root`; `what` names the region in error messages."""
    from dolfinx.io.gmsh import model_to_mesh

    with gmsh_session() if comm.rank == root else _nothing() as gmsh:
        error = None
        if comm.rank == root:
            try:
                build(gmsh)
            except InputError as exc:
                error = ("input", exc.field, exc.message)
            except Exception as exc:  # noqa: BLE001  (re-raised on every rank below)
                error = ("gmsh", None, f"gmsh failed to mesh {what}: {exc}")
        error = comm.bcast(error, root=root)
        if error and error[0] == "input":
            raise InputError(error[1], error[2])
        if error:
            raise RuntimeError(error[2])
        model = gmsh.model if comm.rank == root else None
        return model_to_mesh(model, comm, root, gdim=2, partitioner=partitioner())
