"""The official bindings' own test files, run against mjcffi with the import swapped.

`python -m conformance` runs every `*_test.py` that ships in the installed
`mujoco` package (from the mujoco-core wheel) with `import mujoco` rewritten
to `import mjcffi as mujoco`, in a temporary folder, and reports the pass
count per file; `--write` writes CONFORMANCE.md.  The official files are
never copied into this repository.

`python -m conformance mujoco_py` does the same for mujoco-py's own test files
(from its wheel on PyPI) against mjcffi.sim; see conformance/mujoco_py.py.
"""
