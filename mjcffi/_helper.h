/* Declarations of mjcffi's own C helper (mjcffi/_helper.c), read by
   mjcffi/_build.py into the cffi cdef after the generated _cdef.h.
   Hand-written: the helper is not generated. */

/* mjVERSION_HEADER of the headers this module was compiled against. */
int mjcffi_header_version(void);

/* The message of the mju_error caught by the last guarded call on this thread
   (an mjcffi_guard_* function or mjcffi_step), or NULL if that call caught
   none.  Clears it: a second call returns NULL.  The text stays valid until
   the next error caught on this thread. */
const char* mjcffi_take_error(void);

/* mj_step(m, d) nstep times under one guard (cffi releases the GIL around
   it): 0 when all steps ran, 1 when an mju_error was caught.  After 1, d is
   left mid-step; see mjcffi/_errors.py for how to make it usable again. */
int mjcffi_step(const mjModel* m, mjData* d, int nstep);

/* Unpickle an mjData into `dest`, a fresh mj_makeData of the same model: the
   saved struct (`header`, sizeof(mjData) bytes), its buffer (nbuffer bytes)
   and the used part of its arena, with every pointer moved onto dest's own
   memory.  Returns 0, or 1 when the sizes do not match dest. */
int mjcffi_restore_data(mjData* dest, const char* header, const char* buffer,
                        const char* arena, size_t arena_used);

/* Lay out the arena arrays of d (made for m) as MuJoCo does: ncon contacts, nefc constraint
   rows with nJ Jacobian entries (nJ -1: keep d->nJ), and their dual-solver rows when m's
   solver is dual; every other arena array is dropped.  0, or 1 when the arena is too small
   (or a count negative): then the arena is empty and every row count 0. */
int mjcffi_realloc_con_efc(const mjModel* m, mjData* d, int ncon, int nefc, int nJ);

/* Lay out d's island arrays for nisland islands over nidof dofs, reusing the old island
   block when nothing follows it in the arena, else after everything.  0, or 1 when the
   arena is too small (or a count negative): then no island arrays, nisland = nidof = 0. */
int mjcffi_realloc_island(const mjModel* m, mjData* d, int nisland, int nidof);

/* An mjfTime: CLOCK_MONOTONIC in seconds, for mjcb_time (no Python, no GIL per call). */
mjtNum mjcffi_timer(void);
