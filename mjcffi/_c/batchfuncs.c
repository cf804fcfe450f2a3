// The mjfBatchFunc tasks of mjcffi.batch.Batch.jac and Batch.ray, run by
// mjb_apply on MuJoCo's thread pool.  Compiled into mjcffi._mjcffi by
// mjcffi/_c/build.py; declared, with their argument structs, in batchfuncs.h.
//
// MuJoCo is called unguarded here.  Inside mjb_apply an mju_error is caught
// by the batch itself, per simulation: it records the failure in mjb_status
// and mjb_error and goes on with the other simulations.  MuJoCo leaves a task
// with longjmp, so these functions hold nothing that would need releasing.

#include <stddef.h>

#include <mujoco/mujoco.h>

#include "batchfuncs.h"

// The row of the call's arrays that holds simulation `sim`.
static inline ptrdiff_t batch_row(const int* rows, int sim) {
  return rows ? rows[sim] : sim;
}

void mjcffi_batch_jac(const mjModel* m, mjData* d, int sim, void* arg) {
  const mjcffi_batch_jac_arg* a = (const mjcffi_batch_jac_arg*)arg;
  ptrdiff_t row = batch_row(a->rows, sim);
  int body = a->body[row];

  // the output rows are sized by the batch's model: a caller model of
  // set_models must agree before mj_jac writes 3*m->nv per Jacobian
  if (m->nv != a->nv) {
    mju_error("Batch.jac: the simulation's model has nv %lld, the batch's %d",
              (long long)m->nv, a->nv);
  }
  if (body < 0 || body >= m->nbody) {
    mju_error("Batch.jac: body %d is out of range for a model with %lld bodies", body,
              (long long)m->nbody);
  }

  mj_kinematics(m, d);
  mj_comPos(m, d);
  ptrdiff_t jac = 3 * (ptrdiff_t)a->nv * row;
  mj_jac(m, d, a->jacp + jac, a->jacr + jac, a->point + 3 * row, body);
}

void mjcffi_batch_ray(const mjModel* m, mjData* d, int sim, void* arg) {
  const mjcffi_batch_ray_arg* a = (const mjcffi_batch_ray_arg*)arg;
  ptrdiff_t first = batch_row(a->rows, sim) * (ptrdiff_t)a->nray;

  mj_kinematics(m, d);
  if (m->nflex) {
    mj_flex(m, d);
  }
  for (ptrdiff_t r = first; r < first + a->nray; r++) {
    a->dist[r] = mj_ray(m, d, a->pnt + 3 * r, a->vec + 3 * r, a->geomgroup, a->flg_static,
                        a->bodyexclude[r], a->geomid + r,
                        a->normal ? a->normal + 3 * r : NULL);
  }
}
