"""The results stage: everything a run or a study writes or prints, below which nothing imports.

    log      say (rank-0 lines), Progress (one line in place on a terminal, plain lines in logs)
    tables   CSV rows and JSON summaries, each written whole or not at all
    disk     DiskFull, and the room a run keeps on its disk before each write
    fields   VTX series for ParaView and a PNG of the deformed sheet
    cup      the drawn cup: draw-in, thickness lines, peak thinning, VTX series, force plot, picture

Data flow one way: scene -> problem -> driver -> results. The solver packages import log lines
from here; the results read the problem and driver they are handed.
"""
