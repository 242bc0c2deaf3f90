# hwpts: the two commands are `make reproduce` and `make test`.
PYTHON ?= python3
VENV := .venv
BIN := $(VENV)/bin
STAMP := $(VENV)/.installed

.PHONY: install reproduce test bench readme readme-control docs clean

install: $(STAMP)

$(STAMP): pyproject.toml
	test -x $(BIN)/python || $(PYTHON) -m venv $(VENV)
	$(BIN)/python -m pip install --quiet --upgrade pip
	$(BIN)/python -m pip install --quiet -e ".[test]"
	touch $(STAMP)

reproduce: install
	$(BIN)/hwpts reproduce --out results

test: install
	$(BIN)/python -m pytest -q

# the API reference and user guide, offline, into docs/_build/html (sphinx installed into .venv)
docs: install
	$(BIN)/python -m pip install --quiet -e ".[docs]"
	$(BIN)/python -m sphinx -b html -j 1 --keep-going docs docs/_build/html
	@echo "open docs/_build/html/index.html"

bench: install
	$(BIN)/python -m benchmarks

readme: reproduce
	$(BIN)/python tools/update_readme.py results

readme-control: install
	$(BIN)/hwpts control run --scenario turbulence-a --seed 0 --out results-control
	$(BIN)/python tools/update_readme_control.py results-control

clean:
	rm -rf $(VENV) results results-control .pytest_cache .hypothesis
