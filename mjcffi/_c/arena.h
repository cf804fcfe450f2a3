/* The arena layout of _realloc_con_efc and _realloc_island (arena.c).
   Read by mjcffi/_c/build.py into the cffi cdef, and included by the C files.
   Hand-written. */

/* Lay out the arena arrays of d (made for m) as MuJoCo does: ncon contacts, nefc constraint
   rows with nJ Jacobian entries (nJ -1: keep d->nJ), and their dual-solver rows when m's
   solver is dual; every other arena array is dropped.  0, or 1 when the arena is too small
   (or a count negative): then the arena is empty and every row count 0. */
int mjcffi_realloc_con_efc(const mjModel* m, mjData* d, int ncon, int nefc, int nJ);

/* Lay out d's island arrays for nisland islands over nidof dofs, reusing the old island
   block when nothing follows it in the arena, else after everything.  0, or 1 when the
   arena is too small (or a count negative): then no island arrays, nisland = nidof = 0. */
int mjcffi_realloc_island(const mjModel* m, mjData* d, int nisland, int nidof);
