# The README's two commands: `make demo` and `make test`. Each installs what is missing first.
JOBS ?= 2
export JOBS

.PHONY: demo test bench format build deps clean

demo: build
	@scripts/demo.sh

# test.sh installs what is missing itself, as the first phase of its time table.
test:
	@scripts/test.sh

bench: build
	@scripts/bench.sh

build: deps
	@scripts/build.sh release

format: deps
	@git ls-files '*.cpp' '*.h' | xargs clang-format -i

deps:
	@scripts/install-deps.sh

clean:
	rm -rf build out
