"""The results stage: the progress line of a run."""

import io

from shellform.results.log import Progress


class Terminal(io.StringIO):
    def isatty(self):
        return True


def test_progress_rewrites_one_line_on_a_terminal_and_keeps_notes():
    out = Terminal()
    p = Progress("stroke", 1.0, " mm", 30.0, stream=out)
    p.increment(0.25, 10, 80, "increment  10 ...")
    p.increment(0.5, 20, 170, "increment  20 ...")
    text = out.getvalue()
    assert text.count("\r") == 2 and "\n" not in text  # one line, rewritten
    assert "stroke 15 of 30 mm: 20 increments, 170 iterations" in text.split("\r")[-1]
    assert "s left" in text.split("\r")[-1]
    p.close()
    assert out.getvalue().endswith("\n")


def test_progress_in_a_log_keeps_the_plain_increment_lines():
    log = io.StringIO()  # not a terminal
    p = Progress("load factor", 1.0, stream=log)
    p.increment(0.5, 3, 12, "increment   3  lambda 0.5")
    p.note("  cut back: ...")
    assert log.getvalue() == "increment   3  lambda 0.5\n  cut back: ...\n"
