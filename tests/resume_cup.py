"""The short cup of the resume tests and a run of it killed right after its first report
(only the checkpoint survives), shared by test_contact.py and test_mpi.py's two-rank script."""

from pathlib import Path

from shellform import scene
from shellform.contact import run as contact_run
from shellform.contact.semi_inverse import SemiInverseDriver

ROOT = Path(__file__).resolve().parents[1]


def cup():
    """The paper's cup on 6 x 6, 1 mm of stroke in steps of 0.05 to 0.1 mm, a report at 0.5 mm."""
    return scene.load(ROOT / "demos" / "square_cup.toml").changed({
        "mesh.n": 6, "tools.stroke": 1.0, "process.report": [0.5], "process.initial_step_mm": 0.05,
        "process.max_step_mm": 0.1, "output.vtx": False, "output.png": False, "output.fld": False,
        "process.springback": False})


class Killed(Exception):
    pass


def killed_after_first_report(outdir, scene=None, saves: int = 1) -> None:
    """Run `scene` (cup()) into outdir and die as its checkpoint number `saves` (the first: at
    the first report) is written."""
    save, done = SemiInverseDriver.save_checkpoint, []

    def save_and_die(self, *args, **kwargs):
        save(self, *args, **kwargs)
        done.append(1)
        if len(done) >= saves:
            raise Killed

    SemiInverseDriver.save_checkpoint = save_and_die
    try:
        contact_run.run(scene or cup(), outdir)
    except Killed:
        pass
    finally:
        SemiInverseDriver.save_checkpoint = save
