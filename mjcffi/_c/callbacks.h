/* The Python side of MuJoCo's mjcb_* callbacks: cffi `extern "Python"`
   trampolines, read by mjcffi/_c/build.py into the cffi cdef only (this is not
   C: the compiled module never #includes it).  One per global, each with its
   global's function type, so that its address can be stored there; the
   Python bodies are attached with @ffi.def_extern in mjcffi/_support/callbacks.py.
   Hand-written: not generated. */

extern "Python" {
  /* mjfGeneric */
  void mjcffi_py_mjcb_passive(const mjModel* m, mjData* d);
  void mjcffi_py_mjcb_control(const mjModel* m, mjData* d);
  /* mjfConFilt */
  int mjcffi_py_mjcb_contactfilter(const mjModel* m, mjData* d, int geom1, int geom2);
  /* mjfSensor */
  void mjcffi_py_mjcb_sensor(const mjModel* m, mjData* d, int stage);
  /* mjfTime */
  mjtNum mjcffi_py_mjcb_time(void);
  /* mjfAct */
  mjtNum mjcffi_py_mjcb_act_dyn(const mjModel* m, const mjData* d, int id);
  mjtNum mjcffi_py_mjcb_act_gain(const mjModel* m, const mjData* d, int id);
  mjtNum mjcffi_py_mjcb_act_bias(const mjModel* m, const mjData* d, int id);
}

/* The Python side of the legacy mju_user_warning handler (mjcffi/user_handlers.py). */
extern "Python" {
  void mjcffi_py_mju_user_warning(const char* msg);
}
