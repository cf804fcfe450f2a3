// mujoco-py's PID actuators as MuJoCo actuator callbacks (see sim_pid.h).
//
// Two controllers, both in the standard form Kp * (e + I(e)/Ti + Td * de/dt):
// - the PID: position setpoint ctrl, feedback actuator_length; gainprm holds
//   Kp, Ti, integral clamp, Td, derivative smoothing, error deadband;
// - the cascaded controller: an EMA-smoothed position setpoint drives a PID on
//   position whose output, clamped to the velocity limit, is the setpoint of a
//   PI on actuator_velocity; the joint's bias force (gravity, Coriolis) is
//   added.  gainprm holds Kp, Ti, integral clamp, Td, derivative smoothing of
//   the position loop, Kp, Ti, integral clamp of the velocity loop, the EMA
//   factor and the velocity limit.  With a position Kp of 0, ctrl is the
//   velocity setpoint itself.
// Both clamp their output to forcerange unless it is (0, 0), and advance their
// state by one timestep per call, as mujoco-py did (RK4 calls them 4 times a step).
#include <math.h>
#include <mujoco/mujoco.h>
#include "sim_pid.h"

// gainprm indices of the PID
enum {
  PID_KP = 0, PID_TI, PID_IMAX, PID_TD, PID_SMOOTH, PID_DEADBAND
};

// gainprm indices of the cascaded controller
enum {
  CAS_KP = 0, CAS_TI, CAS_IMAX, CAS_TD, CAS_SMOOTH,
  CAS_KP_VEL, CAS_TI_VEL, CAS_IMAX_VEL, CAS_EMA, CAS_VMAX
};

// userdata slots of the PID (mujoco-py's layout: its tests read them)
enum { PID_S_INTEGRAL = 0, PID_S_ERROR, PID_S_DERIVATIVE };

// userdata slots of the cascaded controller
enum {
  CAS_S_ERROR = 0, CAS_S_INTEGRAL, CAS_S_DERIVATIVE, CAS_S_INTEGRAL_VEL, CAS_S_SETPOINT
};

// The error history one PID loop carries from call to call.
typedef struct {
  mjtNum error;         // last error (after the deadband)
  mjtNum integral;      // clamped integral of the error
  mjtNum derivative;    // smoothed derivative of the error
} PidHistory;

// The constants of one PID loop.
typedef struct {
  mjtNum kp;            // proportional gain
  mjtNum ti;            // integral time constant; 0: no integral term
  mjtNum imax;          // the integral stays within [-imax, imax]
  mjtNum td;            // derivative time constant
  mjtNum smooth;        // EMA weight of the new derivative sample (1: no smoothing)
  mjtNum deadband;      // errors smaller than this count as 0
} PidGains;


static mjtNum clamp(mjtNum x, mjtNum lo, mjtNum hi) {
  return fmax(lo, fmin(hi, x));
}


// One step of a PID loop of period dt: the output, with `h` advanced.
// The operations and their order are mujoco-py's, so results match bit for bit.
static mjtNum pid_step(const PidGains* g, mjtNum setpoint, mjtNum feedback, mjtNum dt,
                       PidHistory* h) {
  mjtNum error = setpoint - feedback;
  if (fabs(error) < g->deadband) {
    error = 0.0;
  }
  mjtNum rate = (error - h->error) / dt;
  mjtNum derivative = (1.0 - g->smooth) * h->derivative + g->smooth * rate;
  mjtNum integral = clamp(h->integral + error * dt, -g->imax, g->imax);
  mjtNum integral_term = g->ti != 0 ? integral / g->ti : 0.0;

  h->error = error;
  h->integral = integral;
  h->derivative = derivative;
  return g->kp * (error + integral_term + derivative * g->td);
}


// The control as MuJoCo's built-in actuators see it: clamped to ctrlrange
// (MuJoCo of mujoco-py's time clamped d->ctrl itself before the callbacks ran).
static mjtNum control(const mjModel* m, const mjData* d, int id) {
  mjtNum ctrl = d->ctrl[id];
  if (m->actuator_ctrllimited[id] && !(m->opt.disableflags & mjDSBL_CLAMPCTRL)) {
    ctrl = clamp(ctrl, m->actuator_ctrlrange[2*id], m->actuator_ctrlrange[2*id + 1]);
  }
  return ctrl;
}


// `force` within forcerange, unless forcerange is (0, 0) (mujoco-py's rule).
static mjtNum limit_force(const mjModel* m, int id, mjtNum force) {
  mjtNum lo = m->actuator_forcerange[2*id], hi = m->actuator_forcerange[2*id + 1];
  if (lo != 0.0 || hi != 0.0) {
    force = clamp(force, lo, hi);
  }
  return force;
}


// The bias force on the dof of the hinge or slide joint that actuator `id`
// drives; 0 for other transmissions (set_pid_control refuses those).  mujoco-py
// read qfrc_bias[id], the same dof when actuator i drives dof i.
static mjtNum joint_bias(const mjModel* m, const mjData* d, int id) {
  if (m->actuator_trntype[id] != mjTRN_JOINT) {
    return 0.0;
  }
  int joint = m->actuator_trnid[2*id];
  if (joint < 0 || joint >= m->njnt ||
      (m->jnt_type[joint] != mjJNT_HINGE && m->jnt_type[joint] != mjJNT_SLIDE)) {
    return 0.0;
  }
  return d->qfrc_bias[m->jnt_dofadr[joint]];
}


static mjtNum pid_force(const mjModel* m, const mjData* d, int id, mjtNum* state) {
  const mjtNum* prm = m->actuator_gainprm + mjNGAIN*id;
  PidGains gains = {prm[PID_KP], prm[PID_TI], prm[PID_IMAX], prm[PID_TD], prm[PID_SMOOTH],
                    prm[PID_DEADBAND]};
  PidHistory h = {state[PID_S_ERROR], state[PID_S_INTEGRAL], state[PID_S_DERIVATIVE]};

  mjtNum force = pid_step(&gains, control(m, d, id), d->actuator_length[id],
                          m->opt.timestep, &h);

  state[PID_S_ERROR] = h.error;
  state[PID_S_INTEGRAL] = h.integral;
  state[PID_S_DERIVATIVE] = h.derivative;
  return limit_force(m, id, force);
}


static mjtNum cascade_force(const mjModel* m, const mjData* d, int id, mjtNum* state) {
  const mjtNum* prm = m->actuator_gainprm + mjNGAIN*id;
  mjtNum dt = m->opt.timestep;
  mjtNum ctrl = control(m, d, id);

  // EMA on the position setpoint; at time 0 it starts from the setpoint itself
  mjtNum setpoint = ctrl;
  if (d->time > 0.0) {
    setpoint = prm[CAS_EMA] * state[CAS_S_SETPOINT] + (1 - prm[CAS_EMA]) * ctrl;
  }
  state[CAS_S_SETPOINT] = setpoint;

  // position loop -> desired velocity
  mjtNum velocity = ctrl;
  if (prm[CAS_KP] != 0) {
    PidGains position = {prm[CAS_KP], prm[CAS_TI], prm[CAS_IMAX], prm[CAS_TD],
                         prm[CAS_SMOOTH], 0.0};
    PidHistory h = {state[CAS_S_ERROR], state[CAS_S_INTEGRAL], state[CAS_S_DERIVATIVE]};
    velocity = pid_step(&position, setpoint, d->actuator_length[id], dt, &h);
    state[CAS_S_ERROR] = h.error;
    state[CAS_S_INTEGRAL] = h.integral;
    state[CAS_S_DERIVATIVE] = h.derivative;
  }
  velocity = clamp(velocity, -prm[CAS_VMAX], prm[CAS_VMAX]);

  // velocity loop: a PI, with no error history besides its integral
  PidGains pi = {prm[CAS_KP_VEL], prm[CAS_TI_VEL], prm[CAS_IMAX_VEL], 0.0, 0.0, 0.0};
  PidHistory hv = {0.0, state[CAS_S_INTEGRAL_VEL], 0.0};
  mjtNum force = pid_step(&pi, velocity, d->actuator_velocity[id], dt, &hv);
  state[CAS_S_INTEGRAL_VEL] = hv.integral;

  force += joint_bias(m, d, id);     // gravity compensation
  return limit_force(m, id, force);
}


mjtNum mjcffi_pid_gain(const mjModel* m, const mjData* d, int id) {
  (void)m, (void)d, (void)id;
  return 0.0;
}


mjtNum mjcffi_pid_bias(const mjModel* m, const mjData* d, int id) {
  // the callbacks are global: a model set_pid_control never checked may land here
  if (id < 0 || id >= m->nu || m->nuserdata < MJCFFI_PID_NSTATE * ((long)id + 1)) {
    return 0.0;
  }
  mjtNum* state = d->userdata + MJCFFI_PID_NSTATE*id;
  mjtNum type = m->nuser_actuator > 0 ? m->actuator_user[m->nuser_actuator*id] : 0.0;

  // mujoco-py compared int(user[0]) with 1
  if (type >= MJCFFI_PID_CASCADE && type < MJCFFI_PID_CASCADE + 1) {
    return cascade_force(m, d, id, state);
  }
  return pid_force(m, d, id, state);
}
