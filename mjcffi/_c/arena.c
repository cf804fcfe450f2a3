// The arena layout of the official private _realloc_con_efc and _realloc_island
// (mjcffi/_support/arena.py).  Declared in arena.h.

#include <stddef.h>
#include <stdint.h>
#include <string.h>

#include <mujoco/mujoco.h>
#include <mujoco/mjxmacro.h>

#include "arena.h"

//---------------------------------- the arena ----------------------------------------------------
//
// The contact, constraint and island arrays of an mjData live in its arena, allocated by
// MuJoCo's own mj_arenaAllocByte in a step: contacts at the start, then the constraint rows
// (MJDATA_ARENA_POINTERS_SOLVER in mjxmacro.h), the islands, and the dual solver's and the
// effective metric's arrays.  These two functions lay them out for given counts, as the
// official bindings' private _realloc_con_efc and _realloc_island do, so that arrays
// computed elsewhere (MJX, MuJoCo Warp) can be copied into an mjData.  As there, the dual
// solver's rows come right after the constraint rows (a step puts them after the islands).
// They return 0, or 1 when the arena is too small; then every count they laid out is 0.

// Exported by libmujoco but declared in no public header: bytes from the arena, aligned,
// or NULL when the arena (what the stack leaves of it) is full.
void* mj_arenaAllocByte(mjData* d, size_t bytes, size_t alignment);

// The X-macros' sizes, read from the model m and the data d in scope (put back below).
#undef MJ_M
#define MJ_M(n) m->n
#undef MJ_D
#define MJ_D(n) d->n

// Every arena array gone, every count of rows 0: what a failed layout leaves behind.
static void mjcffi_clear_arena(mjData* d) {
#define X(type, name, nr, nc) d->name = NULL;
  MJDATA_ARENA_POINTERS
#undef X
  d->contact = (mjContact*)d->arena;
  d->parena = 0;
  d->ncon = d->ne = d->nf = d->nl = d->nefc = d->nJ = d->nY = d->nA = 0;
  d->nisland = d->nidof = 0;
  d->efm_active = 0;
  d->nefmK = d->nefmcon = d->nefmT = d->nefmA = d->nefmdof = d->nefmL = 0;
}

// Allocate one X-macro list's arrays in order, or jump to `fail`.
#define MJCFFI_ALLOC(type, name, nr, nc)                                           \
  d->name = (type*)mj_arenaAllocByte(d, sizeof(type) * (size_t)(nr) * (size_t)(nc), \
                                     _Alignof(type));                               \
  if (!d->name) goto fail;

int mjcffi_realloc_con_efc(const mjModel* m, mjData* d, int ncon, int nefc, int nJ) {
  int keep_nJ = d->nJ;
  mjcffi_clear_arena(d);
  if (ncon < 0 || nefc < 0 || nJ < -1) {
    return 1;
  }
  d->ncon = ncon;
  d->nefc = nefc;
  d->nJ = nJ < 0 ? keep_nJ : nJ;   // as the official: an omitted nJ keeps the last one
  d->contact = (mjContact*)mj_arenaAllocByte(d, sizeof(mjContact) * (size_t)ncon,
                                             _Alignof(mjContact));
  if (!d->contact) goto fail;
#define X MJCFFI_ALLOC
  MJDATA_ARENA_POINTERS_SOLVER
  if (mj_isDual(m)) {
    MJDATA_ARENA_POINTERS_DUAL     // rows only: nY and nA are 0 until the solver runs
  }
#undef X
  return 0;
fail:
  mjcffi_clear_arena(d);
  return 1;
}

// Whether an arena array outside the island block ends after `start`, the island block's
// first byte: then the block is not the last thing in the arena and cannot be reused.
static int mjcffi_after_islands(const mjModel* m, const mjData* d, const char* start) {
  int after = 0;
#define X(type, name, nr, nc)                                                      \
  if (d->name && (const char*)d->name + sizeof(type) * (size_t)(nr) * (size_t)(nc) > start) \
    after = 1;
  MJDATA_ARENA_POINTERS_CONTACT
  MJDATA_ARENA_POINTERS_SOLVER
  MJDATA_ARENA_POINTERS_DUAL
  MJDATA_ARENA_POINTERS_EFM
#undef X
  return after;
}

static void mjcffi_clear_islands(mjData* d, size_t parena) {
#define X(type, name, nr, nc) d->name = NULL;
  MJDATA_ARENA_POINTERS_ISLAND
#undef X
  d->nisland = d->nidof = 0;
  d->parena = parena;
}

int mjcffi_realloc_island(const mjModel* m, mjData* d, int nisland, int nidof) {
  // where the island block starts, if it is in the arena
  char* arena = (char*)d->arena;
  char* start = NULL;
#define X(type, name, nr, nc)                                                      \
  if (d->name && (char*)d->name >= arena && (char*)d->name <= arena + d->parena && \
      (!start || (char*)d->name < start))                                          \
    start = (char*)d->name;
  MJDATA_ARENA_POINTERS_ISLAND
#undef X

  // reuse the old block when nothing follows it; else add a new one at the end
  size_t parena = d->parena;
  if (start && !mjcffi_after_islands(m, d, start)) {
    parena = (size_t)(start - arena);
  }
  mjcffi_clear_islands(d, parena);
  if (nisland < 0 || nidof < 0) {
    return 1;
  }
  d->nisland = nisland;
  d->nidof = nidof;
#define X MJCFFI_ALLOC
  MJDATA_ARENA_POINTERS_ISLAND
#undef X
  return 0;
fail:
  mjcffi_clear_islands(d, parena);
  return 1;
}

#undef MJCFFI_ALLOC
#undef MJ_M
#define MJ_M(n) n
#undef MJ_D
#define MJ_D(n) n
