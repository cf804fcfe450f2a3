/* Native mjfBatchFunc tasks of mjcffi.batch.Batch.jac and Batch.ray
   (mjcffi/_c/batchfuncs.c), read by mjcffi/_c/build.py into the cffi cdef after
   the generated cdef.h.  Hand-written.

   mjb_apply(b, ids, nid, func, arg, 0) runs func on MuJoCo's thread pool,
   without the GIL, with a pointer to one of the argument structs below as
   arg.  The inputs and outputs are the call's arrays, one row per selected
   simulation: `rows` maps a simulation index to its row (nsim entries, and
   only the selected ones are read), or is NULL when every simulation is
   selected and row i is simulation i.  The functions call MuJoCo unguarded:
   an mju_error ends the simulation's task in MuJoCo's batch machinery,
   which marks that simulation failed in mjb_status and keeps the message
   for mjb_error, and the other simulations run on. */

/* Batch.jac: per simulation, mj_kinematics, mj_comPos, then mj_jac of
   point[row] on body[row] into jacp[row] and jacr[row] (3 x nv each). */
typedef struct mjcffi_batch_jac_arg_ {
  const int* rows;        /* nsim: simulation -> row; NULL: row = sim */
  int nv;                 /* the row stride of jacp and jacr is 3*nv */
  const int* body;        /* (n,) */
  const mjtNum* point;    /* (n, 3) */
  mjtNum* jacp;           /* (n, 3, nv) */
  mjtNum* jacr;           /* (n, 3, nv) */
} mjcffi_batch_jac_arg;

void mjcffi_batch_jac(const mjModel* m, mjData* d, int sim, void* arg);

/* Batch.ray: per simulation, mj_kinematics, mj_flex if the model has
   flexes, then mj_ray for each of the row's nray rays. */
typedef struct mjcffi_batch_ray_arg_ {
  const int* rows;            /* nsim: simulation -> row; NULL: row = sim */
  int nray;                   /* rays per row */
  const mjtNum* pnt;          /* (n, nray, 3) */
  const mjtNum* vec;          /* (n, nray, 3) */
  const mjtByte* geomgroup;   /* (mjNGROUP,), or NULL for every group */
  mjtBool flg_static;         /* whether static geoms are hit */
  const int* bodyexclude;     /* (n, nray): a body whose geoms are ignored, or -1 */
  mjtNum* dist;               /* (n, nray) */
  int* geomid;                /* (n, nray) */
  mjtNum* normal;             /* (n, nray, 3), or NULL for no normals */
} mjcffi_batch_ray_arg;

void mjcffi_batch_ray(const mjModel* m, mjData* d, int sim, void* arg);
