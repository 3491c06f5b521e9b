# The two commands of the README: `make demo` (main job) and `make test` (the test suite).
# Both create their own virtual environment in .venv from the base Python and install what they use.
PYTHON ?= python3
VENV ?= .venv
PY := $(VENV)/bin/python
STAMP := $(VENV)/.installed

.PHONY: demo test venv lint siconos clean clean-numba-cache chromium regress ci

venv: $(STAMP)

$(STAMP): pyproject.toml setup.py Makefile
	$(PYTHON) -m venv $(VENV)
	$(PY) -m pip install --quiet --upgrade pip
	$(PY) -m pip install --quiet -e '.[test,cad]'
	touch $(STAMP)

demo: $(STAMP)
	$(VENV)/bin/clearbench demo

lint: $(STAMP)
	$(PY) -m ruff check .

# numba's cache is filled once first, in one process (`clearbench compile --jobs 1`: two
# processes compile the same kernels side by side); otherwise every pytest worker and
# every run subprocess of the tests compiles the same kernels cold (minutes of CPU each).
test: $(STAMP) lint siconos chromium
	$(VENV)/bin/clearbench compile --jobs 1
	$(PY) -m pytest -m "not slow" -n auto --dist worksteal --durations=30

# The quick regression suite against the committed baselines (CI runs it after the tests).
regress: $(STAMP)
	$(VENV)/bin/clearbench regress

ci: test regress demo

# Debian's chromium, for the test that opens the report in a headless browser; never fails the
# build (the test skips, saying why, where it cannot be installed).
chromium:
	@if command -v chromium >/dev/null 2>&1; then \
		echo "chromium: installed"; \
	elif [ "$$(id -u)" = "0" ] && command -v apt-get >/dev/null 2>&1; then \
		echo "chromium: installing Debian's chromium with apt-get"; \
		( apt-get update -qq && DEBIAN_FRONTEND=noninteractive apt-get install -y -qq chromium >/dev/null ) \
			|| echo "chromium: WARNING: apt-get could not install chromium; the browser test will be skipped"; \
	else \
		echo "chromium: not installed (needs root and apt-get); the browser test will be skipped"; \
	fi

# Debian's python3-siconos (Siconos 4.4) for the side-by-side validation; never fails the build.
siconos:
	@if env -i PATH=/usr/bin:/bin /usr/bin/python3 -c "import siconos.numerics, siconos.kernel, siconos.mechanics.joints" >/dev/null 2>&1; then \
		echo "siconos: python3-siconos is installed"; \
	elif [ "$$(id -u)" = "0" ] && command -v apt-get >/dev/null 2>&1; then \
		echo "siconos: installing python3-siconos with apt-get"; \
		( apt-get update -qq && DEBIAN_FRONTEND=noninteractive apt-get install -y -qq python3-siconos >/dev/null ) \
			|| echo "siconos: WARNING: apt-get could not install python3-siconos; Siconos comparisons will be skipped"; \
	else \
		echo "siconos: python3-siconos not installed (needs root and apt-get); Siconos comparisons will be skipped"; \
	fi

clean:
	rm -rf $(VENV) build *.egg-info

# numba's on-disk cache does not notice edits to a compiled function's callees (an inlined
# kernel edited in another module): after editing numba kernels, drop the caches.
clean-numba-cache:
	find . -not -path './$(VENV)/*' \( -name '*.nbi' -o -name '*.nbc' \) -delete
	rm -rf $${XDG_CACHE_HOME:-$$HOME/.cache}/clearbench-numba $${XDG_CACHE_HOME:-$$HOME/.cache}/clearbench-numba-checkouts
