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


# ------------------------------------------------------------- hard cases
#
# Small scenes that each model only what their case needs, for the accuracy
# report (python -m mjcffi.accuracy) and tests/test_hard_cases.py.

# A chaotic double pendulum: two hinges, no contacts, no damping, so its
# energy is conserved and its error grows quickly with the timestep.
DOUBLE_PENDULUM = """
<mujoco model="double pendulum">
  <option timestep="0.001" integrator="RK4">
    <flag contact="disable" constraint="disable"/>
  </option>
  <worldbody>
    <body name="upper" pos="0 0 2">
      <joint name="shoulder" type="hinge" axis="0 1 0"/>
      <geom type="capsule" fromto="0 0 0 0 0 -0.5" size="0.02" mass="1"/>
      <body name="lower" pos="0 0 -0.5">
        <joint name="elbow" type="hinge" axis="0 1 0"/>
        <geom type="capsule" fromto="0 0 0 0 0 -0.5" size="0.02" mass="1"/>
      </body>
    </body>
  </worldbody>
  <keyframe>
    <key name="start" qpos="2.0 1.0"/>
  </keyframe>
</mujoco>
"""

# A free tee spinning about its intermediate principal axis (the body y axis:
# principal inertias 0.090, 0.061, 0.031 about body z, y, x), without gravity:
# the rotation is unstable, and the 0.1 % off-axis spin in the keyframe grows
# until the tee flips (the Dzhanibekov effect, after about 1.5 s), while energy
# and angular momentum are conserved.  The geoms put the centre of mass at the
# body origin, so the spin is about the centre of mass and the tee stays put.
DZHANIBEKOV = """
<mujoco model="dzhanibekov">
  <option timestep="0.001" integrator="RK4" gravity="0 0 0">
    <flag contact="disable" constraint="disable"/>
  </option>
  <worldbody>
    <body name="tee">
      <freejoint name="free"/>
      <geom type="box" size="0.3 0.1 0.05" pos="-0.1 0 0" mass="1"/>
      <geom type="box" size="0.02 0.4 0.02" pos="0.2 0 0" mass="0.5"/>
    </body>
  </worldbody>
  <keyframe>
    <key name="spin" qpos="0 0 0 1 0 0 0" qvel="0 0 0 0.01 10 0.01"/>
  </keyframe>
</mujoco>
"""

# A stack of four boxes resting on the floor: stiff, sustained contact.  The
# upper boxes sit a few centimetres off centre and turned about z, so the
# contacts carry off-centre loads (an exactly aligned stack is symmetric and
# drifts by nothing but round-off); every centre of mass stays well inside
# the top face of the box below.
BOX_STACK = """
<mujoco model="box stack">
  <option timestep="0.002"/>
  <worldbody>
    <geom name="floor" type="plane" size="2 2 0.1"/>
    <body name="box1" pos="0 0 0.1"><freejoint/><geom type="box" size="0.1 0.1 0.1" mass="1"/></body>
    <body name="box2" pos="0.03 0.01 0.3" euler="0 0 10"><freejoint/><geom type="box" size="0.1 0.1 0.1" mass="1"/></body>
    <body name="box3" pos="0 0.03 0.5" euler="0 0 -5"><freejoint/><geom type="box" size="0.1 0.1 0.1" mass="1"/></body>
    <body name="box4" pos="0.04 0.02 0.7" euler="0 0 20"><freejoint/><geom type="box" size="0.1 0.1 0.1" mass="1"/></body>
  </worldbody>
</mujoco>
"""

# A chain, released horizontal, whose links alternate between 1 kg and 1 g (a
# 1000:1 mass ratio; the inertia matrix has a condition number of about 1e5),
# with joint damping: the fastest damping mode, the largest eigenvalue of
# M^-1 B times the timestep, is about 7, past the stability limit of explicit
# integration (2 for Euler, 2.8 for RK4), which blows up within a few hundredths
# of a second; implicitfast integrates the damping implicitly and stays stable.
MASS_RATIO_CHAIN = """
<mujoco model="mass-ratio chain">
  <option timestep="0.002" integrator="implicitfast">
    <flag contact="disable"/>
  </option>
  <default><joint type="hinge" axis="0 1 0" damping="0.05"/></default>
  <worldbody>
    <body name="l1" pos="0 0 2"><joint/><geom type="capsule" fromto="0 0 0 0.2 0 0" size="0.01" mass="1"/>
      <body name="l2" pos="0.2 0 0"><joint/><geom type="capsule" fromto="0 0 0 0.2 0 0" size="0.01" mass="0.001"/>
        <body name="l3" pos="0.2 0 0"><joint/><geom type="capsule" fromto="0 0 0 0.2 0 0" size="0.01" mass="1"/>
          <body name="l4" pos="0.2 0 0"><joint/><geom type="capsule" fromto="0 0 0 0.2 0 0" size="0.01" mass="0.001"/>
            <body name="l5" pos="0.2 0 0"><joint/><geom type="capsule" fromto="0 0 0 0.2 0 0" size="0.01" mass="1"/>
              <body name="l6" pos="0.2 0 0"><joint/><geom type="capsule" fromto="0 0 0 0.2 0 0" size="0.01" mass="0.001"/>
              </body>
            </body>
          </body>
        </body>
      </body>
    </body>
  </worldbody>
</mujoco>
"""

HARD_CASES = {"double_pendulum": DOUBLE_PENDULUM, "dzhanibekov": DZHANIBEKOV,
              "box_stack": BOX_STACK, "mass_ratio_chain": MASS_RATIO_CHAIN}
