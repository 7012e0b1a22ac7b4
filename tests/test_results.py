"""The results stage: the progress line of a run."""

import io
import logging
import sys

import numpy as np
import pytest

from shellform.results import log


class Terminal(io.StringIO):
    def isatty(self):
        return True


@pytest.fixture
def shown():
    """The console handler of the command line on streams of the test's own; removed after."""
    handlers = []

    def install(level=logging.INFO, out=None, err=None):
        handlers.append(log.console(level, out, err))
        return handlers[-1]

    yield install
    for h in handlers:
        log.quiet(h)


def test_progress_rewrites_one_line_on_a_terminal_and_keeps_notes(monkeypatch, shown):
    """One line rewritten in place, as wide as the terminal (80 columns: 79 characters, so that
    no increment wraps onto a new line); the time left from the progress since the first
    increment, once three are done."""
    monkeypatch.setenv("COLUMNS", "80")
    out = Terminal()
    shown(out=out)
    p = log.Progress("stroke", 1.0, " mm", 30.0)
    p.increment(0.1, 1, 8, "increment   1 ...")
    p.increment(0.25, 10, 80, "increment  10 ...")
    p.increment(0.5, 20, 170, "increment  20 ...")
    text = out.getvalue()
    assert text.count("\r") == 3 and "\n" not in text  # one line, rewritten
    lines = text.split("\r")[1:]
    assert all(len(line) == 79 for line in lines)
    assert "s left" not in lines[0]  # under three increments: no estimate yet
    assert "stroke 15 of 30 mm: 20 increments, 170 iterations" in lines[-1] and "s left" in lines[-1]
    p.note("  cut back: ...")
    assert out.getvalue().endswith("\n  cut back: ...\n")  # the note below the in-place line
    p.increment(0.6, 21, 175, "increment  21 ...")
    p.close()
    assert out.getvalue().endswith("\n") and out.getvalue().count("\r") == 4


def test_progress_in_a_log_keeps_the_plain_increment_lines(shown):
    out = io.StringIO()  # not a terminal
    shown(out=out)
    p = log.Progress("load factor", 1.0)
    p.increment(0.5, 3, 12, "increment   3  lambda 0.5")
    p.note("  cut back: ...")
    p.close()
    assert out.getvalue() == "increment   3  lambda 0.5\n  cut back: ...\n"
    out.truncate(0), out.seek(0)  # a tool scene's log: the stroke too
    log.Progress("stroke", 1.0, " mm", 30.0).increment(0.5, 3, 12, "increment   3  lambda 0.5")
    assert out.getvalue() == "increment   3  lambda 0.5  (stroke 15 mm)\n"


def test_verbose_shows_every_increment_on_a_terminal_and_quiet_only_the_closing_line(shown):
    out, err = Terminal(), io.StringIO()
    verbose = shown(logging.DEBUG, out, err)
    log.Progress("load factor", 1.0).increment(0.5, 3, 12, "increment   3")
    assert out.getvalue() == "increment   3\n"
    log.quiet(verbose)
    out, err = io.StringIO(), io.StringIO()
    shown(log.RESULT, out, err)
    log.Progress("load factor", 1.0).increment(0.5, 3, 12, "increment   3")
    log.say("shellform: writing the tables")
    log.say("shellform: done", level=log.RESULT)
    log.say("shellform: stopped", file=sys.stderr)
    assert out.getvalue() == "shellform: done\n" and err.getvalue() == "shellform: stopped\n"


def test_the_library_prints_nothing_unless_asked(capsys):
    """Without a handler (a script, a notebook): no line on stdout or stderr, warnings neither."""
    log.Progress("load factor", 1.0).increment(0.5, 3, 12, "increment   3")
    log.say("a line")
    log.say("a stop", file=sys.stderr)
    assert capsys.readouterr() == ("", "")


def test_keeler_brazier_curve():
    """FLC0 = (23.3 + 14.13 t) n / 0.21 % (engineering); the left side keeps the thinning
    -(eps1 + eps2) constant, the right side rises by 0.6 per engineering minor strain."""
    import numpy as np
    import pytest

    from shellform.results import fld

    t, n = 0.78, 0.2589
    e0 = np.log(1 + (23.3 + 14.13 * t) * n / 0.21 / 100)
    curve = fld.keeler_brazier(t, n)
    assert fld.flc0(t, n) == pytest.approx(e0, rel=1e-14)
    assert curve(0.0) == pytest.approx(e0, rel=1e-14)
    for minor in (-0.3, -0.1, -0.01):
        assert curve(minor) + minor == pytest.approx(e0, rel=1e-14)
    for minor in (0.05, 0.2):
        assert np.expm1(curve(minor)) - np.expm1(e0) == pytest.approx(0.6 * np.expm1(minor), rel=1e-12)
    assert fld.margins(0.2, 0.0, curve) == pytest.approx(e0 - 0.2, rel=1e-14)


def test_the_thickness_picture_is_white_at_zero():
    """The thickness-strain colours: limits symmetric about zero (so white is an unchanged
    thickness, not the middle of the range), and the label says so."""
    import numpy as np

    from shellform.results import cup

    (lo, hi), cmap, label = cup.thickness_colours(np.array([-0.128, 0.0, 0.18, 0.02]))
    assert (lo, hi) == (-0.18, 0.18) and cmap == "coolwarm"
    assert "white 0" in label and "symmetric" in label
    assert cup.thickness_colours(np.zeros(3))[0] == (-1.0, 1.0)  # an undeformed sheet: a valid range


def test_the_force_axis_says_the_whole_cup():
    """DrawingProblem reports the whole cup's force (the modelled region's times its copies):
    the axis says whole cup, and from what."""
    from shellform.results import cup

    assert cup.force_label(4) == "punch force on the whole cup (kN)\n(the modelled quarter's x 4)"
    assert cup.force_label(2).endswith("(the modelled half's x 2)")
    assert cup.force_label(1) == "punch force on the whole cup (kN)"


def test_json_has_no_nan_or_infinity(tmp_path):
    """write_json writes strict JSON: a non-finite number (the draw-in at an angle the rim does not
    reach) is null, numpy numbers and arrays plain ones."""
    import json

    from shellform.results.tables import write_json

    write_json(tmp_path / "s.json", {"rim_0deg": float("nan"), "a": [np.inf, np.float64(2.5)], "n": np.int64(3),
                                     "nested": {"b": -np.inf, "ok": True, "arr": np.array([1.0, np.nan])}})
    text = (tmp_path / "s.json").read_text()
    assert json.loads(text, parse_constant=lambda c: pytest.fail(c)) == {
        "rim_0deg": None, "a": [None, 2.5], "n": 3, "nested": {"b": None, "ok": True, "arr": [1.0, None]}}
