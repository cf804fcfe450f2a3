/* Declarations of mjcffi's own C helper (mjcffi/_helper.c), read by
   mjcffi/_build.py into the cffi cdef after the generated _cdef.h.
   Hand-written: the helper is not generated. */

/* mjVERSION_HEADER of the headers this module was compiled against. */
int mjcffi_header_version(void);
