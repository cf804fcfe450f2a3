/* Pickled mjData and MJB bytes checked before MuJoCo reads them (unpickle.c).
   Read by mjcffi/_c/build.py into the cffi cdef, and included by the C files.
   Hand-written. */

/* Pickling an mjData (see mjcffi/data.py): its header is mjData's bytes up to `buffer`
   (mjcffi_data_header_size()); its layout (mjcffi_data_layout_size() bytes, written by
   mjcffi_save_layout) holds a tag, the signature and each arena array as an offset, -1 for
   none.  mjcffi_save_layout returns 1 when the header holds something of this process alone
   (thread pool, stack in use): mjcffi_clear_local zeroes that in a copy of the header.
   mjcffi_restore_data checks a header, a buffer (nbuffer bytes), the used arena (parena
   bytes) and a layout against m and against d, a fresh mj_makeData of m, and only then
   copies them into d: buffer pointers stay d's own, arena pointers come from the checked
   offsets, and d keeps its plugin instances.  It returns 0, or 1 with the reason (the field
   and its bound) in `why` (which may be NULL, nwhy 0), d untouched. */
size_t mjcffi_data_header_size(void);
size_t mjcffi_data_layout_size(void);
int mjcffi_save_layout(const mjData* d, char* layout);
void mjcffi_clear_local(char* header);
int mjcffi_restore_data(const mjModel* m, mjData* d, const char* header, size_t nheader,
                        const char* buffer, size_t nbuffer, const char* arena, size_t narena,
                        const char* layout, size_t nlayout, char* why, size_t nwhy);

/* Whether `mjb` (n bytes) holds exactly what its sizes describe, the rule mj_loadModelBuffer
   applies only after allocating that much: 0, or 1 with why.  Bytes too short for the sizes,
   or of another layout, pass: MuJoCo refuses them before allocating, with its message. */
int mjcffi_check_mjb(const char* mjb, size_t n, char* why, size_t nwhy);
