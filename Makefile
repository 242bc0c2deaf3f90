# hwpts: the two commands are `make reproduce` and `make test`.
PYTHON ?= python3
VENV := .venv
BIN := $(VENV)/bin
STAMP := $(VENV)/.installed

.PHONY: install reproduce test bench readme clean

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

bench: install
	$(BIN)/python -m benchmarks

readme: reproduce
	$(BIN)/python tools/update_readme.py results

clean:
	rm -rf $(VENV) results .pytest_cache .hypothesis
