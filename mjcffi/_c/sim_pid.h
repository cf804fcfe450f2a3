/* mujoco-py's PID actuators (mjcffi/_c/sim_pid.c), read by mjcffi/_c/build.py into the cffi cdef.

   Both functions have MuJoCo's mjfAct signature; mjcffi/sim/_pid.py installs them as
   mjcb_act_gain and mjcb_act_bias.  MuJoCo calls them only for actuators whose gaintype
   (biastype) is mjGAIN_USER (mjBIAS_USER).

   The actuator's user[0] picks the controller: 1 is the cascaded position-velocity
   controller, anything else (or no user field) the PID.  Actuator `id` keeps its
   state in d->userdata[MJCFFI_PID_NSTATE*id ...], MJCFFI_PID_NSTATE numbers:
     PID:      integral error, error, smoothed derivative of the error
     cascaded: position error, position integral error, smoothed derivative of the
               position error, velocity integral error, smoothed position setpoint */

#define MJCFFI_PID_NSTATE 5
#define MJCFFI_PID_CASCADE 1

/* The gain of every user-gain actuator: 0, so that its force is the bias alone. */
mjtNum mjcffi_pid_gain(const mjModel* m, const mjData* d, int id);

/* The force of the PID or cascaded controller of actuator `id` (updating its state).
   An actuator whose state does not fit in nuserdata gets 0 and no state is written. */
mjtNum mjcffi_pid_bias(const mjModel* m, const mjData* d, int id);
