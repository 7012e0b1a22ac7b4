"""The constitutive time per element evaluation of Hill 1979, Hill 1948 and Yld2000-2d on the
2,450-cell NUMISHEET'93 aluminium cup (35 x 35) to 3 mm, the three one after the other, twice
(docs/material.md). About 5 minutes on 2 cores.

    python scripts/yield_function_cup_cost.py
"""
import sys, json, time
from shellform import scene, run
h79 = {"material.yield_function": "hill79", "material.r": 0.6425, "material.m": 2.0,
       "material.r0": 0.0, "material.r45": 0.0, "material.r90": 0.0}
h48 = {"material.yield_function": "hill48", "material.r": 1.0, "material.r0": 0.71, "material.r45": 0.58, "material.r90": 0.70}
y2k = {"material.yield_function": "yld2000", "material.r": 1.0, "material.r0": 0.71, "material.r45": 0.58,
       "material.r90": 0.70, "material.r_b": 1.0, "material.sigma0": 1.0, "material.sigma45": 1.0,
       "material.sigma90": 1.0, "material.sigma_b": 1.0, "material.a": 8.0}
base = {"mesh.n": 35, "output.vtx": False, "output.vtu": False, "output.png": False, "output.fld": False,
        "process.springback": False, "tools.stroke": 3.0, "process.report": []}  # the scene's steps, in mm
rows = []
for rep in range(2):
    for name, ch in (("hill79", h79), ("hill48", h48), ("yld2000", y2k)):
        s = scene.load("demos/numisheet93_aluminium.toml").changed({**base, **ch})
        summ = run.run(s, f"/tmp/yield_function_cup_cost_{name}_{rep}")
        t = summ["wall_time_s"]
        rows.append((name, rep, summ["element_evaluations"]["run"], t["constitutive_s"], t["element_s"], summ["newton_iterations"]))
        print(name, rep, "evaluations", summ["element_evaluations"]["run"], "constitutive_s %.2f" % t["constitutive_s"],
              "per evaluation ms %.1f" % (1e3 * t["constitutive_s"] / summ["element_evaluations"]["run"]),
              "element_s %.2f" % t["element_s"], "iterations", summ["newton_iterations"], flush=True)
