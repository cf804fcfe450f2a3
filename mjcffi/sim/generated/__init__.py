"""mujoco-py's `mujoco_py.generated` path: `const`, MuJoCo's constants under mujoco-py's names."""
