# serialkin — the two set-up commands of the README:
#   make run    reproduce the chapter into out/chapter/report.html
#   make test   the whole test suite (peers and headless-browser tests included)
# Each creates .venv when missing and installs the project into it.

PYTHON ?= python3
VENV   := .venv
PY     := $(VENV)/bin/python
STAMP_RUN  := $(VENV)/.stamp-run
STAMP_TEST := $(VENV)/.stamp-test

.PHONY: run test test-autograd lint bench docs browser-deps clean bytecode

# The kernels the chapter report uses (`serialkin warmup --list` lists every feature; the
# report compiles in its own workers whatever else it needs), and collision, which no
# section calls: compiled by `make test` while its extras install, it was the last
# process running there (15 s on one core); here it packs beside the others. Not
# arm-angle nor ik-all-near (nearly ideal arms): `make test`'s warm-up compiles them, one
# in each process, while its extras install, then loads the features cached here.
RUN_FEATURES := kinematics ik ik-all ik-all-general ik-methods workspace tracking collision

# Packages install with uv when it can (from PyPI, as pip would: the same versions; it
# downloads, unpacks and byte-compiles in parallel: on this project's 2-core machines the
# project's requirements in 9 s instead of 18-23 s, the test extras in 8-10 s instead of
# 24 s), else with pip: `install` tries uv, and pip when uv is missing or fails. The venv
# is made without pip (ensurepip and pip's upgrade took 4.5 s of `make run`): uv is
# installed beside it by the machine's own pip (`.venv/uv`, a single binary), and `pip`
# puts pip into the venv only when a step needs it (the fallback, the autograd extras).
UV := $(VENV)/uv/bin/uv
pip = { $(PY) -m pip --version >/dev/null 2>&1 || { $(PY) -m ensurepip >/dev/null \
	  && { $(PY) -m pip install --quiet --upgrade pip || true; }; }; } && $(PY) -m pip
install = { [ -x $(UV) ] && $(UV) pip install --quiet --python $(PY) --compile-bytecode $(1); } \
	  || { $(pip) install --quiet $(1); }
# (uv's freeze without --quiet: some uv releases print no list with it, astral-sh/uv#16178)
freeze = { { [ -x $(UV) ] && $(UV) pip freeze --python $(PY) --exclude-editable; } \
	  || { $(pip) freeze --exclude-editable; }; }

$(PY):
	$(PYTHON) -m venv --without-pip $(VENV)

# Tried again by every make while it is missing (a venv of an older layout, an offline
# first run); its failure is not fatal: `install` then uses pip.
$(UV): | $(PY)
	-PIP_ROOT_USER_ACTION=ignore $(PYTHON) -m pip install --quiet --retries 1 --timeout 15 \
	  --target $(VENV)/uv "uv>=0.5,<1"

$(STAMP_RUN): pyproject.toml | $(PY) $(UV)
	$(call install,-e .)
	touch $@

# The test extras' own requirements, installed beside the project without reinstalling it
# (so that a warm-up running meanwhile keeps its imports) and constrained to what is
# already installed (so that nothing it imports changes under it).
TEST_EXTRAS := dev bench docs mesh xacro dist paths

$(STAMP_TEST): $(STAMP_RUN)
	$(PY) -c "import tomllib; o = tomllib.load(open('pyproject.toml', 'rb'))['project']\
	['optional-dependencies']; print('\n'.join(r for e in '$(TEST_EXTRAS)'.split() for r in o[e]))" \
	  > $(VENV)/test-extras.txt
	$(freeze) > $(VENV)/installed.txt
	$(call install,-r $(VENV)/test-extras.txt -c $(VENV)/installed.txt)
	touch $@

# serialkin's own modules byte-compiled (pip byte-compiles the installed packages; the
# project is installed editable, and where PYTHONDONTWRITEBYTECODE is set, as on this
# project's machines, every process compiled serialkin's sources again: 0.4 s of each
# process that imports most of it, of which make test starts about a hundred). Only
# what changed since the last run is compiled again.
bytecode: $(STAMP_RUN)
	@$(PY) -m compileall -q -j 0 src

# `serialkin warmup` compiles the kernels into numba's on-disk cache first, one process
# per feature on every core, with a progress bar (seconds when the cache is already
# filled). The cache notices source edits by itself (serialkin/_jit.py: each kernel is
# stamped with a hash of its module and of every module it imports). The report, the
# docs and the benchmarks compile anything left in the foreground (SERIALKIN_COMPILE=wait)
# rather than run it as Python meanwhile: their figures are the compiled results.
run: $(STAMP_RUN) bytecode
	$(VENV)/bin/serialkin warmup $(RUN_FEATURES)
	SERIALKIN_COMPILE=wait $(VENV)/bin/serialkin chapter --out out/chapter

# Headless Chromium for the viewer tests and ffmpeg for MP4 animations (Debian packages).
# Failure is not fatal: those tests then skip and say why.
browser-deps:
	@command -v chromium >/dev/null 2>&1 && command -v chromedriver >/dev/null 2>&1 \
	  && command -v ffmpeg >/dev/null 2>&1 || \
	  ( (apt-get update -qq && DEBIAN_FRONTEND=noninteractive apt-get install -y -qq \
	      chromium chromium-driver ffmpeg >/dev/null) \
	    || echo "browser-deps: could not install chromium/ffmpeg; those tests will be skipped" )

# On a fresh machine the test extras and the browser install while the kernels compile
# (the three overlap: downloads and unpacking wait on the network and the disk, the
# warm-up on the CPU); the suite starts when all three are done, and fails the target
# if any did.
test: $(STAMP_RUN) bytecode
	@set -e; \
	  $(MAKE) --no-print-directory $(STAMP_TEST) & extras=$$!; \
	  $(MAKE) --no-print-directory browser-deps & browser=$$!; \
	  $(VENV)/bin/serialkin warmup --all; \
	  wait $$extras; wait $$browser
	$(PY) -m pytest -n 2 --dist loadfile --no-loadscope-reorder --ignore=tests/autograd

# The differentiable kinematics of serialkin.torch and serialkin.jax (issue 35): their
# extras (torch, jax) and the benchmark's peer (pytorch-kinematics) install into the same
# venv, constrained to what is already installed, and tests/autograd runs. `make test`
# leaves that folder to this target and .ci/run calls both; here a missing extra fails the
# run (SERIALKIN_AUTOGRAD_REQUIRED) instead of skipping it. TORCH_INDEX offers PyTorch's
# CPU wheels beside PyPI, whose default Linux torch pulls gigabytes of CUDA libraries.
# TORCH_PIN keeps pip on a CPU build where PyPI's newer CUDA build is also offered (a
# local +cpu wheel in pip's find-links sorts above PyPI's build of the same version).
TORCH_INDEX ?= https://download.pytorch.org/whl/cpu
TORCH_PIN ?= torch==2.13.*
AUTOGRAD_EXTRAS := torch jax autograd-bench
STAMP_AUTOGRAD := $(VENV)/.stamp-autograd

$(STAMP_AUTOGRAD): $(STAMP_TEST)
	$(PY) -c "import tomllib; o = tomllib.load(open('pyproject.toml', 'rb'))['project']\
	['optional-dependencies']; print('\n'.join(r for e in '$(AUTOGRAD_EXTRAS)'.split() for r in o[e]))" \
	  > $(VENV)/autograd-extras.txt
	$(freeze) > $(VENV)/installed-autograd.txt
	@# PyTorch's index only when its host resolves (else pip retries it for every package)
	index=$$($(PY) -c "import socket, urllib.parse as u; \
	  socket.getaddrinfo(u.urlsplit('$(TORCH_INDEX)').hostname, 443)" 2>/dev/null \
	  && echo "--extra-index-url $(TORCH_INDEX)"); \
	$(pip) install --quiet $$index \
	  -r $(VENV)/autograd-extras.txt "$(TORCH_PIN)" -c $(VENV)/installed-autograd.txt
	touch $@

test-autograd: $(STAMP_AUTOGRAD) bytecode
	$(VENV)/bin/serialkin warmup kinematics ik ik-methods
	SERIALKIN_AUTOGRAD_REQUIRED=1 $(PY) -m pytest -n 2 --dist loadfile tests/autograd

lint: $(STAMP_TEST)
	$(VENV)/bin/ruff check src tests benchmarks examples

# The documentation site into site/ (strict: a warning fails); open site/index.html.
docs: $(STAMP_TEST) bytecode
	SERIALKIN_COMPILE=wait DISABLE_MKDOCS_2_WARNING=true NO_MKDOCS_2_WARNING=1 \
	  $(PY) -m mkdocs build --strict

bench: $(STAMP_TEST) bytecode
	SERIALKIN_COMPILE=wait $(PY) benchmarks/run_all.py

clean:
	rm -rf $(VENV) out site .pytest_cache
