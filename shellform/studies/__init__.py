"""Convergence studies: error against wall time, written as CSV tables and plots.

Each study is a function ``run(outdir, ...) -> list[dict]`` and a ``shellform study NAME`` command.
"""
