"""python -m conformance: the same as python -m conformance.report."""

from .report import main

main()
