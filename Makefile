# shellform: `make demo` runs the main job, `make test` the fast lane of the test suite (all but the
# tests marked slow), `make test-slow` the slow lane; CI (.ci/run) runs both; `make docs` the docs site.
# All create .venv with a Python >= 3.12 and install the project on first use (make docs adds the
# docs extra: MkDocs and its plugins, pinned in pyproject.toml).
VENV   := .venv
PY     := $(VENV)/bin/python
STAMP  := $(VENV)/.installed
DOCSTAMP := $(VENV)/.docs-installed
OUT    ?= results/square_cup
# test processes (pytest-xdist): one per core of the 2-core machines the suite is sized for
NPROC  ?= 2
# make venv compiles the numba and FFCx kernels into the user's caches once (WARM=0: not)
WARM   ?= 1

.PHONY: demo test test-slow venv clean bench docs

venv: $(STAMP)

$(STAMP): pyproject.toml scripts/find-python.sh
	@py=$$(scripts/find-python.sh) || exit 1; \
	 echo "shellform: using $$py"; \
	 [ -x $(PY) ] || $$py -m venv $(VENV)
	$(PY) -m pip install -q --upgrade pip
	$(PY) -m pip install -q -e '.[wheel,test]'
	$(PY) -c "import shellform; shellform.check_install()"
ifneq ($(WARM),0)
	@echo "shellform: compiling the kernels once, so that a first run starts at once (a short cup; WARM=0 skips it)"
	$(VENV)/bin/shellform run demos/numisheet93_aluminium.toml -o $(VENV)/warm-up -q --set mesh.n=6 \
	    --set tools.stroke=0.5 --set output.png=false --set output.vtx=false --set output.fld=false
	rm -rf $(VENV)/warm-up
endif
	@touch $(STAMP)

demo: $(STAMP)
	$(VENV)/bin/shellform run demos/square_cup.toml --out $(OUT)
	@echo "shellform: summary.json, cup.pvd (ParaView, pyvista), force_stroke.csv/.png, thickness_*.csv, thickness.png, cup.png in $(OUT) (docs/results.md)"

test: $(STAMP)
	$(PY) -m pytest -q -n $(NPROC) --dist loadfile -m "not slow" tests

test-slow: $(STAMP)
	$(PY) -m pytest -q -n $(NPROC) --dist loadfile -m slow tests

# the site from docs/ (mkdocs.yml) into site/: first the checks that the studies' tables the pages
# include are their files (scripts/docs_include.py) and that the numbers the prose cites from them
# are theirs (scripts/docs_numbers.py), then MkDocs with every warning an error
docs: $(DOCSTAMP)
	$(PY) scripts/docs_include.py --check
	$(PY) scripts/docs_numbers.py
	NO_MKDOCS_2_WARNING=1 $(PY) -m mkdocs build --strict
	@echo "shellform: the docs site is in site/ (open site/index.html)"

$(DOCSTAMP): $(STAMP)
	$(PY) -m pip install -q -e '.[docs]'
	@touch $(DOCSTAMP)

clean:
	rm -rf $(VENV) results site
