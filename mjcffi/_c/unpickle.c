// What an unpickled mjData or an MJB must pass before MuJoCo reads it: the layout of a
// pickled mjData checked and restored, and an MJB's sizes against its length.  Declared
// in unpickle.h.

#include <limits.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <mujoco/mujoco.h>
#include <mujoco/mjxmacro.h>

#include "unpickle.h"

//---------------------------------- pickling an mjData ------------------------------------------
//
// A pickled mjData is (model, header, buffer, arena, layout): the header is mjData's own bytes up
// to `buffer` (sizes, statistics, counts), the buffer its nbuffer bytes, the arena the parena
// bytes in use (the stack above them is scratch), and the layout below.  Neither holds an
// address.  Unpickling takes every buffer pointer from a fresh mj_makeData of the model and every
// arena pointer from an offset that must lie, with room for its count, inside the arena bytes.
// It refuses any count that the model and the arena cannot hold, and any index that a step
// follows before recomputing it, before it writes anything.

// layout: tag | signature | the offset in the arena of each of its arrays (-1: none)
static const char mjcffi_tag[8] = {'m', 'j', 'c', 'f', 'f', 'i', 'D', '1'};

enum {
#define X(type, name, nr, nc) MJCFFI_ARENA_##name,
  MJDATA_ARENA_POINTERS
#undef X
  MJCFFI_NARENA
};

#define MJCFFI_INFO_SIZE offsetof(mjData, buffer)
#define MJCFFI_AT_SIGNATURE sizeof(mjcffi_tag)
#define MJCFFI_AT_OFFSETS (MJCFFI_AT_SIGNATURE + sizeof(uint64_t))
#define MJCFFI_LAYOUT_SIZE (MJCFFI_AT_OFFSETS + MJCFFI_NARENA * sizeof(int64_t))
#define MJCFFI_FIELD_SIZE(field) sizeof(((mjData*)0)->field)

size_t mjcffi_data_header_size(void) {
  return MJCFFI_INFO_SIZE;
}

size_t mjcffi_data_layout_size(void) {
  return MJCFFI_LAYOUT_SIZE;
}

int mjcffi_save_layout(const mjData* d, char* layout) {
  memcpy(layout, mjcffi_tag, sizeof(mjcffi_tag));
  memcpy(layout + MJCFFI_AT_SIGNATURE, &d->signature, sizeof(uint64_t));
  int64_t offsets[MJCFFI_NARENA];
#define X(type, name, nr, nc)                                                                   \
  offsets[MJCFFI_ARENA_##name] =                                                                \
      d->name ? (int64_t)((const char*)d->name - (const char*)d->arena) : -1;
  MJDATA_ARENA_POINTERS
#undef X
  memcpy(layout + MJCFFI_AT_OFFSETS, offsets, sizeof(offsets));

  // what belongs to this process alone: the thread pool, and the stack with its frame address
  // (empty at rest; left in use by a caught error, or seen so from a callback)
  return d->threadpool || d->threadlock || d->pstack || d->pbase;
}

void mjcffi_clear_local(char* header) {
#define MJCFFI_ZERO(field) memset(header + offsetof(mjData, field), 0, MJCFFI_FIELD_SIZE(field));
  MJCFFI_ZERO(threadpool) MJCFFI_ZERO(threadlock) MJCFFI_ZERO(pstack) MJCFFI_ZERO(pbase)
#undef MJCFFI_ZERO
}

// the int counts of a saved mjData, each checked to be >= 0 first
#define MJCFFI_COUNTS                                                                           \
  C(ncon) C(ne) C(nf) C(nl) C(nefc) C(nJ) C(efm_active) C(nefmK) C(nefmcon) C(nefmT) C(nefmA)  \
  C(nefmdof) C(nefmL) C(nY) C(nA) C(nisland) C(nidof) C(ntree_awake) C(nbody_awake)           \
  C(nparent_awake) C(nv_awake)

typedef struct {
  mjtSize narena, nbuffer;
  size_t pstack, pbase, parena;
  uintptr_t threadpool;
  int nplugin;
#define C(n) int n;
  MJCFFI_COUNTS
#undef C
} mjcffi_saved;

// Refuse: say why (which field, which bound) and return 1.
static int mjcffi_refuse(char* why, size_t nwhy, const char* format, ...) {
  va_list args;
  va_start(args, format);
  vsnprintf(why, nwhy, format, args);
  va_end(args);
  return 1;
}

// Whether an arena array at `offset` (-1: none) of `count` entries of `size` bytes, aligned to
// `align`, lies inside the parena bytes in use.
static int mjcffi_check_arena_array(const char* name, int64_t offset, int64_t count, size_t size,
                                    size_t align, size_t parena, char* why, size_t nwhy) {
  if (offset == -1) {
    return 0;
  }
  if (offset < 0 || (uint64_t)offset > parena || (uint64_t)offset % align) {
    return mjcffi_refuse(why, nwhy, "%s: arena offset %lld is not an offset in [0, parena = %zu] "
                         "aligned to %zu", name, (long long)offset, parena, align);
  }
  if (count < 0 || (uint64_t)count > (parena - (uint64_t)offset) / size) {
    return mjcffi_refuse(why, nwhy, "%s: %lld entries of %zu bytes at arena offset %lld overrun "
                         "parena = %zu", name, (long long)count, size, (long long)offset, parena);
  }
  return 0;
}

// Entry i of `field`, an array of d, as the saved buffer holds it (laid out as d's own).
static int mjcffi_saved_int(const mjData* d, const char* buffer, const void* field, int64_t i) {
  int value;
  memcpy(&value, buffer + ((const char*)field - (const char*)d->buffer) + i * sizeof(int),
         sizeof(int));
  return value;
}

static mjtNum mjcffi_saved_num(const mjData* d, const char* buffer, const void* field,
                               int64_t i) {
  mjtNum value;
  memcpy(&value, buffer + ((const char*)field - (const char*)d->buffer) + i * sizeof(mjtNum),
         sizeof(mjtNum));
  return value;
}

// Entries [start, start + n) of the saved int array `name` lie in [lo, hi).
#define MJCFFI_CHECK_INDICES(name, start, n, lo, hi)                                           \
  for (int64_t i = (start); i < (int64_t)(start) + (int64_t)(n); i++) {                        \
    int v = mjcffi_saved_int(d, buffer, d->name, i);                                           \
    if (v < (lo) || v >= (hi)) {                                                               \
      return mjcffi_refuse(why, nwhy, #name "[%lld] = %d is outside [%lld, %lld)",             \
                           (long long)i, v, (long long)(lo), (long long)(hi));                 \
    }                                                                                          \
  }

// The delay buffers in d->history, each [user, cursor, times(n), values(n*dim)]: they lie inside
// it (the model comes from the same pickle), and their ring cursors, which a step indexes with,
// are integers in [0, n).
static int mjcffi_check_history(const mjModel* m, const mjData* d, const char* buffer,
                                const char* what, int n, const int* history,
                                const int* historyadr, const int* dim, char* why, size_t nwhy) {
  for (int i = 0; i < n; i++) {
    int nsample = history[2*i];
    if (nsample <= 0) {
      continue;
    }
    int64_t end = (int64_t)historyadr[i] + 2 + (int64_t)nsample * (1 + (dim ? dim[i] : 1));
    if (historyadr[i] < 0 || (dim && dim[i] < 0) || end > m->nhistory) {
      return mjcffi_refuse(why, nwhy, "the model's history buffer of %s %d (address %d, %d "
                           "samples) overruns nhistory = %lld", what, i, historyadr[i], nsample,
                           (long long)m->nhistory);
    }
    mjtNum cursor = mjcffi_saved_num(d, buffer, d->history, (int64_t)historyadr[i] + 1);
    if (!(cursor >= 0 && cursor < nsample) || cursor != (mjtNum)(int)cursor) {
      return mjcffi_refuse(why, nwhy, "history: the cursor of %s %d is %g, not an integer in "
                           "[0, %d)", what, i, cursor, nsample);
    }
  }
  return 0;
}

// The contents of the saved buffer that a step follows as indices before recomputing them.
static int mjcffi_check_buffer(const mjModel* m, const mjData* d, const mjcffi_saved* s,
                               const char* buffer, char* why, size_t nwhy) {
  // sleep: tree_asleep links the trees of a sleeping island (< 0: awake), then the awake lists
  MJCFFI_CHECK_INDICES(tree_asleep, 0, m->ntree, INT_MIN, m->ntree)
  MJCFFI_CHECK_INDICES(body_awake_ind, 0, s->nbody_awake, 0, m->nbody)
  MJCFFI_CHECK_INDICES(parent_awake_ind, 0, s->nparent_awake, 0, m->nbody)
  MJCFFI_CHECK_INDICES(dof_awake_ind, 0, s->nv_awake, 0, m->nv)

  // tendon paths, kept as they are while a tendon sleeps: wrap_xpos holds 2*nwrap points
  for (int i = 0; i < m->ntendon; i++) {
    int adr = mjcffi_saved_int(d, buffer, d->ten_wrapadr, i);
    int num = mjcffi_saved_int(d, buffer, d->ten_wrapnum, i);
    if (adr < 0 || num < 0 || (int64_t)adr + num > 2 * (int64_t)m->nwrap) {
      return mjcffi_refuse(why, nwhy, "ten_wrapadr[%d] = %d, ten_wrapnum[%d] = %d: the path "
                           "leaves [0, 2*nwrap = %lld)", i, adr, i, num,
                           2 * (long long)m->nwrap);
    }
    MJCFFI_CHECK_INDICES(wrap_obj, adr, num, -2, m->ngeom)
  }

  // delay buffers
  return mjcffi_check_history(m, d, buffer, "actuator", m->nactuator, m->actuator_history,
                              m->actuator_historyadr, NULL, why, nwhy) ||
         mjcffi_check_history(m, d, buffer, "sensor", m->nsensor, m->sensor_history,
                              m->sensor_historyadr, m->sensor_dim, why, nwhy);
}

// The X-macros' sizes: the model's, and the saved data's counts (checked before they are used).
#undef MJ_M
#define MJ_M(n) ((int64_t)m->n)
#undef MJ_D
#define MJ_D(n) ((int64_t)s.n)

int mjcffi_restore_data(const mjModel* m, mjData* d, const char* info, size_t ninfo,
                        const char* buffer, size_t nbuffer, const char* arena, size_t narena,
                        const char* layout, size_t nlayout, char* why, size_t nwhy) {
  // the header's and the layout's sizes, the layout's tag; then the sizes and counts
  if (ninfo != MJCFFI_INFO_SIZE) {
    return mjcffi_refuse(why, nwhy, "does not fit its model: the header has %zu bytes, this "
                         "mjcffi's %zu", ninfo, (size_t)MJCFFI_INFO_SIZE);
  }
  if (nlayout != MJCFFI_LAYOUT_SIZE || memcmp(layout, mjcffi_tag, sizeof(mjcffi_tag))) {
    return mjcffi_refuse(why, nwhy, "the layout (%zu bytes) is not one that this mjcffi "
                         "writes (%zu bytes, tagged)", nlayout, (size_t)MJCFFI_LAYOUT_SIZE);
  }
  mjcffi_saved s;
#define MJCFFI_READ(field)                                                     \
  _Static_assert(sizeof(s.field) == MJCFFI_FIELD_SIZE(field), #field);         \
  memcpy(&s.field, info + offsetof(mjData, field), sizeof(s.field));
  MJCFFI_READ(narena) MJCFFI_READ(nbuffer) MJCFFI_READ(nplugin) MJCFFI_READ(pstack)
  MJCFFI_READ(pbase) MJCFFI_READ(parena) MJCFFI_READ(threadpool)
#define C(n) MJCFFI_READ(n)
  MJCFFI_COUNTS
#undef C
#undef MJCFFI_READ

  // sizes that the model fixes, and what a pickle never holds
  if (s.narena != d->narena || s.nbuffer != d->nbuffer || s.nplugin != d->nplugin) {
    return mjcffi_refuse(why, nwhy, "does not fit its model: narena, nbuffer, nplugin = %lld, "
                         "%lld, %d, but the model's data has %lld, %lld, %d", (long long)s.narena, (long long)s.nbuffer,
                         s.nplugin, (long long)d->narena, (long long)d->nbuffer, d->nplugin);
  }
  if (nbuffer != (size_t)d->nbuffer) {
    return mjcffi_refuse(why, nwhy, "does not fit its model: the buffer has %zu bytes, but "
                         "nbuffer = %lld", nbuffer,
                         (long long)d->nbuffer);
  }
  if (s.pstack || s.pbase || s.threadpool) {
    return mjcffi_refuse(why, nwhy, "pstack, pbase, threadpool = %zu, %zu, %zu: a pickle holds "
                         "no stack and no thread pool", s.pstack, s.pbase, (size_t)s.threadpool);
  }
  if (s.parena > (size_t)s.narena || narena != s.parena) {
    return mjcffi_refuse(why, nwhy, "parena = %zu, but %zu arena bytes and narena = %lld",
                         s.parena, narena, (long long)s.narena);
  }

  // flags: C booleans are 0 or 1, and threadlock is a running thread pool's (so 0)
  static const struct { const char* name; size_t offset; unsigned char most; } flags[] = {
    {"threadlock", offsetof(mjData, threadlock), 0},
    {"flg_energypos", offsetof(mjData, flg_energypos), 1},
    {"flg_energyvel", offsetof(mjData, flg_energyvel), 1},
    {"flg_subtreevel", offsetof(mjData, flg_subtreevel), 1},
    {"flg_rnepost", offsetof(mjData, flg_rnepost), 1},
  };
  for (size_t i = 0; i < sizeof(flags) / sizeof(flags[0]); i++) {
    unsigned char flag = (unsigned char)info[flags[i].offset];
    if (flag > flags[i].most) {
      return mjcffi_refuse(why, nwhy, "%s = %d is outside [0, %d]", flags[i].name, flag,
                           flags[i].most);
    }
  }

  // counts: none negative, each within what the model and the arena can hold
#define C(n) \
  if (s.n < 0) return mjcffi_refuse(why, nwhy, #n " = %d is negative", s.n);
  MJCFFI_COUNTS
#undef C
  int64_t most = s.narena / 4;    // arena entries are at least 4 bytes (int), contacts more
  const struct { const char* name; int64_t value, bound; } bounded[] = {
    {"ne + nf + nl", (int64_t)s.ne + s.nf + s.nl, s.nefc},
    {"nisland", s.nisland, m->ntree},
    {"nidof", s.nidof, m->nv},
    {"ntree_awake", s.ntree_awake, m->ntree},
    {"nbody_awake", s.nbody_awake, m->nbody},
    {"nparent_awake", s.nparent_awake, m->nbody},
    {"nv_awake", s.nv_awake, m->nv},
    {"efm_active", s.efm_active, 2},
    {"nefmT", s.nefmT, m->ntendon},
    {"nefmA", s.nefmA, m->nactuator},
    {"ncon", s.ncon, s.narena / (int64_t)sizeof(mjContact)},
    {"nefc", s.nefc, most}, {"nJ", s.nJ, most}, {"nY", s.nY, most}, {"nA", s.nA, most},
    {"nefmK", s.nefmK, most}, {"nefmcon", s.nefmcon, most}, {"nefmdof", s.nefmdof, most},
    {"nefmL", s.nefmL, most},
  };
  for (size_t i = 0; i < sizeof(bounded) / sizeof(bounded[0]); i++) {
    if (bounded[i].value > bounded[i].bound) {
      return mjcffi_refuse(why, nwhy, "%s = %lld exceeds %lld", bounded[i].name,
                           (long long)bounded[i].value, (long long)bounded[i].bound);
    }
  }

  // solver statistics: at most mjNSOLVER iterations are recorded per island
  for (int i = 0; i < mjNISLAND; i++) {
    int niter;
    memcpy(&niter, info + offsetof(mjData, solver_niter) + i * sizeof(int), sizeof(int));
    if (niter < 0 || niter > mjNSOLVER) {
      return mjcffi_refuse(why, nwhy, "solver_niter[%d] = %d is outside [0, mjNSOLVER = %d]",
                           i, niter, mjNSOLVER);
    }
  }

  // arena arrays: each inside the arena bytes, with room for its count
  int64_t offsets[MJCFFI_NARENA];
  memcpy(offsets, layout + MJCFFI_AT_OFFSETS, sizeof(offsets));
#define X(type, name, nr, nc)                                                                  \
  if (mjcffi_check_arena_array(#name, offsets[MJCFFI_ARENA_##name], (nr) * (int64_t)(nc),       \
                               sizeof(type), _Alignof(type), s.parena, why, nwhy)) {            \
    return 1;                                                                                  \
  }
  MJDATA_ARENA_POINTERS
#undef X

  if (mjcffi_check_buffer(m, d, &s, buffer, why, nwhy)) {
    return 1;
  }

  // All checked: copy.  Buffer pointers stay d's own and arena pointers come from the offsets;
  // the plugin ids and instances stay d's own too (two datas must not share an instance).
  uintptr_t* plugins = NULL;
  if (d->nplugin) {
    plugins = (uintptr_t*)malloc(2 * sizeof(uintptr_t) * d->nplugin);
    if (!plugins) {
      return mjcffi_refuse(why, nwhy, "out of memory");
    }
    for (int i = 0; i < d->nplugin; i++) {
      plugins[2*i] = (uintptr_t)d->plugin[i];
      plugins[2*i + 1] = d->plugin_data[i];
    }
  }
  void* buffer_now = d->buffer;
  void* arena_now = d->arena;
  uintptr_t threadpool = d->threadpool;
  memcpy(d, info, MJCFFI_INFO_SIZE);
  d->buffer = buffer_now;
  d->arena = arena_now;
  d->threadpool = threadpool;
  memcpy(&d->signature, layout + MJCFFI_AT_SIGNATURE, sizeof(uint64_t));
#define X(type, name, nr, nc)                                                                  \
  d->name = offsets[MJCFFI_ARENA_##name] < 0 ? NULL                                            \
                                             : (type*)((char*)arena_now + offsets[MJCFFI_ARENA_##name]);
  MJDATA_ARENA_POINTERS
#undef X
  memcpy(buffer_now, buffer, nbuffer);
  memcpy(arena_now, arena, narena);
  for (int i = 0; i < d->nplugin; i++) {
    d->plugin[i] = (int)plugins[2*i];
    d->plugin_data[i] = plugins[2*i + 1];
  }
  free(plugins);
  return 0;
}

#undef MJ_M
#define MJ_M(n) n
#undef MJ_D
#define MJ_D(n) n


//---------------------------------- MJB bytes -----------------------------------------------------
//
// mj_loadModelBuffer allocates the model that an MJB's sizes describe before it compares them with
// the bytes it was given, so one corrupted size can make it allocate gigabytes first.  This applies
// its final rule beforehand: the bytes hold exactly the header, the sizes, the structs and the
// arrays that those sizes describe.  (Sizes it would refuse, negative or too large, describe a
// wrong byte count too, or none that fits in a double exactly: refused here as well.)

#define MJCFFI_MJB_NHEADER 5    // ints before the sizes: id, sizeof(mjtNum), nsize, version, nptr

int mjcffi_check_mjb(const char* mjb, size_t n, char* why, size_t nwhy) {
  int nsize = 0;
#define X(name) nsize += _Generic(((mjModel*)0)->name, mjtSize: 1, default: 0);
  MJMODEL_SIZES
#undef X
  size_t at = MJCFFI_MJB_NHEADER * sizeof(int);
  int header[MJCFFI_MJB_NHEADER];
  if (n < at + nsize * sizeof(mjtSize)) {
    return 0;                     // too short: MuJoCo refuses it and says why
  }
  memcpy(header, mjb, sizeof(header));
  if (header[2] != nsize) {
    return 0;                     // another layout: likewise
  }

  // the sizes, as mj_loadModelBuffer reads them (-1 is a legal njmax or nconmax)
  mjModel model;
  mjModel* m = &model;
  memset(m, 0, sizeof(mjModel));
  const char* sizes = mjb + at;
#define X(name)                                                                  \
  if (_Generic(m->name, mjtSize: 1, default: 0)) {                               \
    mjtSize size;                                                                \
    memcpy(&size, sizes, sizeof(mjtSize));                                       \
    sizes += sizeof(mjtSize);                                                    \
    m->name = size;                                                              \
  }
  MJMODEL_SIZES
#undef X

  // the byte count that mj_loadModelBuffer requires (floating point: no overflow)
  size_t flags = offsetof(mjModel, flg_adhesion) + sizeof(mjtBool) -
                 offsetof(mjModel, flg_gravcomp);          // the mjtBool flg_* fields
  double expected = (double)(at + nsize * sizeof(mjtSize) + flags + sizeof(mjOption) +
                             sizeof(mjVisual) + sizeof(mjStatistic));
  {
    MJMODEL_POINTERS_PREAMBLE(m)
#define X(type, name, nr, nc) expected += (double)sizeof(type) * (double)(m->nr) * (double)(nc);
    MJMODEL_POINTERS
#undef X
  }
  if (expected != (double)n) {
    return mjcffi_refuse(why, nwhy, "the MJB holds %zu bytes, but its sizes describe %.0f",
                         n, expected);
  }
  return 0;
}
