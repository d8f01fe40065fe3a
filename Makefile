# Two commands on a fresh machine:  make demo  |  make test
# Both create .venv idempotently. torch==2.13.0 is installed first and alone so pip takes the
# local CPU wheel (a bare "torch" requirement would pull several GB of CUDA packages); the CAD
# kernels are pinned in pyproject.toml (build123d 0.12 + cadquery 2.8, both on OCP 7.9).

PYTHON ?= python3
VENV   := .venv
BIN    := $(VENV)/bin
NODE_DIR := .cache/node
OUT    ?= out

.PHONY: demo test lint bench slow clean review-bundle

$(BIN)/python:
	$(PYTHON) -m venv $(VENV)
	$(BIN)/python -m pip install --quiet --upgrade pip

$(VENV)/.torch: | $(BIN)/python
	$(BIN)/python -m pip install --quiet torch==2.13.0
	touch $@

$(VENV)/.demo-deps: pyproject.toml $(VENV)/.torch
	$(BIN)/python -m pip install --quiet -e '.[cad,view,learn]'
	touch $@

$(VENV)/.dev-deps: pyproject.toml $(VENV)/.torch
	$(BIN)/python -m pip install --quiet -e '.[dev]'
	touch $@

# The Khronos glTF validator (npm package) used by the export tests.
$(NODE_DIR)/node_modules/gltf-validator/package.json:
	@command -v npm >/dev/null || { echo "npm not found: the glTF validator test will be skipped"; exit 0; }
	npm install --silent --no-fund --no-audit --prefix $(NODE_DIR) gltf-validator

# The review page's viewer: woodcam/review/viewer_src.js + three.js from npm, bundled by esbuild
# into one file that is committed (installs need no npm; the page works offline).
review-bundle:
	npm install --silent --no-fund --no-audit --prefix $(NODE_DIR) three@0.187.0 esbuild@0.28.2
	NODE_PATH=$(NODE_DIR)/node_modules $(NODE_DIR)/node_modules/.bin/esbuild \
	  woodcam/review/viewer_src.js --bundle --minify --format=iife --target=es2020 \
	  --legal-comments=none --outfile=woodcam/review/viewer.bundle.js
	cp $(NODE_DIR)/node_modules/three/LICENSE woodcam/review/THREE_LICENSE

demo: $(VENV)/.demo-deps
	$(BIN)/woodcam demo --out $(OUT)

# Lint and type-check the package first (rules in pyproject.toml: [tool.ruff], [tool.mypy]).
lint: $(VENV)/.dev-deps
	$(BIN)/ruff check woodcam
	$(BIN)/mypy

# Debian's Chromium for the review-page tests: installed when this runs as root with apt;
# otherwise those tests skip and say why. Never fails the build.
$(NODE_DIR)/.chromium:
	@mkdir -p $(NODE_DIR)
	@command -v chromium >/dev/null 2>&1 || { [ "$$(id -u)" = 0 ] && command -v apt-get >/dev/null 2>&1 \
	  && { apt-get install -y -qq chromium >/dev/null 2>&1 || { apt-get update -qq >/dev/null 2>&1 \
	  && apt-get install -y -qq chromium >/dev/null 2>&1; }; }; } \
	  || echo "chromium not installed: the review page tests will be skipped"
	@touch $@

# pytest exits 5 when it collects no test: that is a failure here, not a pass.
test: lint $(VENV)/.dev-deps $(NODE_DIR)/node_modules/gltf-validator/package.json $(NODE_DIR)/.chromium
	$(BIN)/python -m pytest; rc=$$?; \
	if [ $$rc -eq 5 ]; then echo "make test: pytest collected no tests" >&2; exit 1; fi; exit $$rc

bench: $(VENV)/.dev-deps
	$(BIN)/python -m pytest -m bench -s -p no:randomly

slow: $(VENV)/.dev-deps
	$(BIN)/python -m pytest -m slow

clean:
	rm -rf $(VENV) $(NODE_DIR) $(OUT) .pytest_cache
