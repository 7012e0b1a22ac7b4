"""One run of a scene: scene -> problem -> driver -> results, whatever its effects.

    summary = run(scene, outdir, scene_path=path, trace=False, resume=False)
    print(summary.closing_line()); sys.exit(summary.exit_status())

A run logs what it does to the logger "shellform" and prints nothing itself
(shellform.results.log: console() shows it as the command line does).

The scene's route solves it and writes its files and summary.json; each route first claims
the output folder (results.run_folder.start: checked writable, before any computation):

    "shell"   the linear shell: one solve of K q = f (shellform.linear, results.shell)
    "sheet"   the nonlinear elastic-plastic sheet stepped along its load path
              (shellform.nonlinear.run)
    "tools"   deep drawing between rigid tools, the sheet's route with contact
              (shellform.contact.run)

The two nonlinear routes take the Newton driver's controls from the scene's [process] in one
place (nonlinear.problem.scene_controls). Each returns a results.summary.Summary: the content
of summary.json, its closing line and the exit status. Only the tools resume from a checkpoint.
"""

import time
from pathlib import Path

from mpi4py import MPI

from shellform import effects
from shellform import _jit as jit
from shellform.errors import InputError
from shellform.results import run_folder
from shellform.results.summary import Summary
from shellform.scene import Scene

ROUTES = {effects.LINEAR: "shell", effects.SHEET: "sheet", effects.TOOLS: "tools"}


def route(s: Scene) -> str:
    """The route a scene takes: the solver its effects select (shellform.effects.route)."""
    return ROUTES[s.route]


def _shell(s: Scene, outdir: Path, comm, scene_path) -> Summary:
    from shellform import linear
    from shellform.results import shell

    run_folder.start(outdir, s, scene_path, comm=comm)
    t0 = time.perf_counter()
    res = linear.solve(s, comm)
    return shell.write(outdir, s, res, time.perf_counter() - t0)


def run(s: Scene, outdir, *, scene_path=None, trace: bool = False, resume: bool = False,
        comm=MPI.COMM_WORLD, listeners=()) -> Summary:
    """Solve the scene into outdir (a folder this run owns: run_folder.start); scene_path: its
    file, for run.json; trace: the tools log every contact pass, Newton step and iterate;
    resume: the tools continue from the last converged state in outdir (InputError("resume")
    for the other routes); listeners: the caller's (shellform.results.listeners.Listener), told
    of a tool or sheet scene's start, increments, reports, checkpoints (tools), stop and end
    after the run's own (ValueError for the linear shell, which has no increments)."""
    outdir = Path(outdir)
    way = route(s)
    if resume and way != "tools":
        raise InputError("resume", "only tool scenes (a [tools] section) resume from a checkpoint")
    if listeners and way == "shell":
        raise ValueError("listeners: the linear shell's solve has no increments to tell them of")
    if way != "shell" and not jit.compiled():
        from shellform.results.log import say

        say("shellform: compiling the element and material kernels: the sheet's element loops, the section "
            "update and the return map (once per machine and version: one to two minutes)")
    if s.nonlinear and "plasticity" in s.effects:
        from shellform.results.log import say

        say(s.hill79().describe())  # the material as it is taken, a table's extrapolation stated
    if way == "tools":
        from shellform.contact import run as tools

        return tools.run(s, outdir, comm, trace=trace, resume=resume, scene_path=scene_path, listeners=listeners)
    if way == "sheet":
        from shellform.nonlinear import run as sheet

        return sheet.run(s, outdir, comm, scene_path=scene_path, listeners=listeners)
    return _shell(s, outdir, comm, scene_path)
