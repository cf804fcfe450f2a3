"""Small embedded scenes that need no files.

DEFAULT is what `python -m mjcffi` simulates: free bodies of three geom types
falling onto a plane (contacts, friction, a free joint each) beside a
three-link arm driven by motors (hinges, actuators, sensors).

PENDULUM is the smallest useful model, for measuring what a binding adds
around MuJoCo: one hinge, one motor, one sensor.
"""

PENDULUM = """
<mujoco model="pendulum">
  <worldbody>
    <body>
      <joint name="hinge" axis="0 1 0"/>
      <geom type="capsule" fromto="0 0 0 0 0 -1" size=".05"/>
    </body>
  </worldbody>
  <actuator><motor joint="hinge"/></actuator>
  <sensor><jointpos joint="hinge"/></sensor>
</mujoco>
"""

DEFAULT = """
<mujoco model="mjcffi default scene">
  <option timestep="0.002"/>
  <worldbody>
    <light pos="0 0 3"/>
    <geom name="floor" type="plane" size="3 3 0.1"/>
    <body name="ball" pos="-0.4 0 0.6">
      <freejoint/>
      <geom type="sphere" size="0.08" mass="0.5"/>
    </body>
    <body name="box" pos="0 0.1 0.8" euler="20 30 0">
      <freejoint/>
      <geom type="box" size="0.07 0.05 0.04" mass="0.4"/>
    </body>
    <body name="capsule" pos="0.3 -0.1 1.0" euler="0 60 0">
      <freejoint/>
      <geom type="capsule" size="0.04 0.1" mass="0.3"/>
    </body>
    <body name="upper" pos="1 0 0.1">
      <joint name="shoulder" type="hinge" axis="0 1 0" damping="0.1"/>
      <geom type="capsule" fromto="0 0 0 0 0 0.4" size="0.04"/>
      <body name="fore" pos="0 0 0.4">
        <joint name="elbow" type="hinge" axis="0 1 0" damping="0.1"/>
        <geom type="capsule" fromto="0 0 0 0 0 0.3" size="0.035"/>
        <body name="hand" pos="0 0 0.3">
          <joint name="wrist" type="hinge" axis="1 0 0" damping="0.05"/>
          <geom type="box" size="0.05 0.03 0.02"/>
          <site name="tip" pos="0 0 0.05"/>
        </body>
      </body>
    </body>
  </worldbody>
  <actuator>
    <motor joint="shoulder" gear="20" ctrlrange="-1 1"/>
    <motor joint="elbow" gear="10" ctrlrange="-1 1"/>
    <motor joint="wrist" gear="5" ctrlrange="-1 1"/>
  </actuator>
  <sensor>
    <framepos objtype="site" objname="tip"/>
    <jointpos joint="elbow"/>
  </sensor>
</mujoco>
"""
