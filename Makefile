.PHONY: run test bench
run:
	bash scripts/run.sh
test:
	bash scripts/test.sh
bench:
	.venv/bin/python tests/bench/bench_object.py
	.venv/bin/python tests/bench/bench_incremental.py
