"""mujoco-py's `mujoco_py.generated` path: `const`, MuJoCo's constants under mujoco-py's
names, and `functions`, MuJoCo's functions with mujoco-py's signatures (both generated;
mjcffi.sim.functions is the public module of the latter)."""
