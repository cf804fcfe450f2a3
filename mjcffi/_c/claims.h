/* The spec claims of claims.c, for Python: a spec and its elements take one thread at a
   time.  Read by mjcffi/_c/build.py into the cffi cdef, and included by claims.c.
   Hand-written. */

/* The number of specs held by a call now, all threads together: Python tests it before
   asking mjcffi_element_check. */
extern int mjcffi_spec_holds;

/* Hold spec s for this thread (the holding thread may nest): 0, or 1 with a
   MJCFFI_ERROR_SPEC_BUSY error pending when another thread holds it.  func names the
   call in the message.  Each 0 is matched by one mjcffi_spec_leave. */
int mjcffi_spec_enter(const mjSpec* s, const char* func);
void mjcffi_spec_leave(const mjSpec* s);

/* 0 when no other thread holds the spec of `element`, else 1 with the error pending. */
int mjcffi_element_check(const mjsElement* element, const char* func);
