"""Benchmarks: mjcffi beside the official bindings, in one process, as ratios."""
