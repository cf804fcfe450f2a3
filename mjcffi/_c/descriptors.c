/* mjcffi._descriptors: the fields of the struct classes, read in C.

   A CPython extension beside the cffi module (which has no way to define Python
   types).  It serves the one path that every field read takes, so that reading a
   scalar (m.nq) or a cached view of moving memory (d.efc_force) costs no Python
   frame and no cffi conversion:

   - `Holder`, the C base of mjcffi's Struct: the address of the C struct it shows
     (found once, on the first read, through `obj._locate()`) and `_dyn`, the list
     of cached views of moving memory (see DynamicArray in _support/views.py);
   - `Field`, a subclass of `property` bound to its struct class: given an instance
     of it, its get reads a scalar at its offset in the struct, or returns the cached
     view of a moving array while the words of the struct that define it (its
     pointer, its counts) are as when it was made.  Anything else (another class, no
     address yet, a changed key, a field it was not told about) goes to the
     property's own getter, the Python code, which refreshes the cache.

   Built against the limited API (one abi3 module, as the cffi one): Field's own
   data lies after property's, at an offset read when the module loads. */

#define PY_SSIZE_T_CLEAN
#include <Python.h>
#include <stddef.h>
#include <stdint.h>
#include <string.h>

/* ------------------------------------------------------------------ Holder */

typedef struct {
    PyObject_HEAD
    char *addr;        /* the struct's address; NULL until found (or after a move) */
    PyObject *dyn;     /* list of cache entries of the moving arrays, or NULL */
} Holder;

static PyTypeObject *holder_type;
static PyObject *str_locate;

static int holder_traverse(PyObject *self, visitproc visit, void *arg) {
    Py_VISIT(((Holder *)self)->dyn);
    Py_VISIT(Py_TYPE(self));      /* a heap type's instances visit their type */
    return 0;
}

static int holder_clear(PyObject *self) {
    Py_CLEAR(((Holder *)self)->dyn);
    return 0;
}

static void holder_dealloc(PyObject *self) {
    PyTypeObject *type = Py_TYPE(self);
    PyObject_GC_UnTrack(self);
    holder_clear(self);
    freefunc release = (freefunc)PyType_GetSlot(type, Py_tp_free);
    release(self);
    Py_DECREF(type);
}

static PyObject *holder_get_dyn(PyObject *self, void *closure) {
    PyObject *dyn = ((Holder *)self)->dyn;
    if (dyn == NULL)
        Py_RETURN_NONE;
    Py_INCREF(dyn);
    return dyn;
}

static int holder_set_dyn(PyObject *self, PyObject *value, void *closure) {
    if (value != NULL && value != Py_None && !PyList_CheckExact(value)) {
        PyErr_SetString(PyExc_TypeError, "_dyn must be a list or None");
        return -1;
    }
    PyObject *old = ((Holder *)self)->dyn;
    ((Holder *)self)->dyn = (value == NULL || value == Py_None) ? NULL : value;
    Py_XINCREF(((Holder *)self)->dyn);
    Py_XDECREF(old);
    return 0;
}

static PyObject *holder_forget(PyObject *self, PyObject *unused) {
    /* The struct moved (or went): find its address again, and drop the views. */
    ((Holder *)self)->addr = NULL;
    holder_clear(self);
    Py_RETURN_NONE;
}

static PyGetSetDef holder_getset[] = {
    {"_dyn", holder_get_dyn, holder_set_dyn,
     "the cached views of moving memory (see DynamicArray), or None", NULL},
    {NULL}
};

static PyMethodDef holder_methods[] = {
    {"_forget_memory", holder_forget, METH_NOARGS,
     "Forget the struct's address and the cached views of moving memory: it moved."},
    {NULL}
};

static PyType_Slot holder_slots[] = {
    {Py_tp_doc, "The C base of mjcffi's struct wrappers: the address of the struct shown, "
                "found on first use, and the cached views of its moving memory."},
    {Py_tp_new, PyType_GenericNew},
    {Py_tp_traverse, holder_traverse},
    {Py_tp_clear, holder_clear},
    {Py_tp_dealloc, holder_dealloc},
    {Py_tp_getset, holder_getset},
    {Py_tp_methods, holder_methods},
    {0, NULL}
};

static PyType_Spec holder_spec = {
    "mjcffi._descriptors.Holder", sizeof(Holder), 0,
    Py_TPFLAGS_DEFAULT | Py_TPFLAGS_BASETYPE | Py_TPFLAGS_HAVE_GC, holder_slots
};

/* The struct's address, found once through obj._locate() (an int; 0: none). */
static char *address(PyObject *obj) {
    Holder *holder = (Holder *)obj;
    if (holder->addr != NULL)
        return holder->addr;
    PyObject *found = PyObject_CallMethodObjArgs(obj, str_locate, NULL);
    if (found == NULL) {
        PyErr_Clear();          /* the property's getter says what is wrong */
        return NULL;
    }
    void *where = PyLong_Check(found) ? PyLong_AsVoidPtr(found) : NULL;
    Py_DECREF(found);
    if (where == NULL)
        PyErr_Clear();
    holder->addr = where;
    return where;
}

/* ------------------------------------------------------------------- Field */

enum { UNBOUND, I8, U8, I16, U16, I32, U32, I64, U64, F32, F64, BOOL, MOVING };
#define MAXKEY 8

typedef struct {
    int kind;
    PyObject *owner;                /* the struct class it reads (a strong reference) */
    Py_ssize_t offset;              /* a scalar's byte offset */
    Py_ssize_t index;               /* a moving array's entry in Holder.dyn */
    int nkey;                       /* its key: words at these byte offsets */
    Py_ssize_t key[MAXKEY];
} FieldData;

static PyTypeObject *field_type;
static Py_ssize_t property_size;    /* where FieldData starts in a Field */
static descrgetfunc property_get;
static traverseproc property_traverse;
static inquiry property_clear;
static destructor property_dealloc;

#define DATA(self) ((FieldData *)((char *)(self) + property_size))

static PyObject *read_scalar(const char *at, int kind) {
    switch (kind) {
    case I8: { int8_t v; memcpy(&v, at, 1); return PyLong_FromLong(v); }
    case U8: { uint8_t v; memcpy(&v, at, 1); return PyLong_FromLong(v); }
    case I16: { int16_t v; memcpy(&v, at, 2); return PyLong_FromLong(v); }
    case U16: { uint16_t v; memcpy(&v, at, 2); return PyLong_FromLong(v); }
    case I32: { int32_t v; memcpy(&v, at, 4); return PyLong_FromLong(v); }
    case U32: { uint32_t v; memcpy(&v, at, 4); return PyLong_FromUnsignedLong(v); }
    case I64: { int64_t v; memcpy(&v, at, 8); return PyLong_FromLongLong(v); }
    case U64: { uint64_t v; memcpy(&v, at, 8); return PyLong_FromUnsignedLongLong(v); }
    case F32: { float v; memcpy(&v, at, 4); return PyFloat_FromDouble(v); }
    case F64: { double v; memcpy(&v, at, 8); return PyFloat_FromDouble(v); }
    case BOOL: return PyBool_FromLong(*(const unsigned char *)at != 0);
    }
    return NULL;
}

/* The cached view of a moving array, or NULL (no error set) when it must be made
   again: the entry is (copy of the key words: bytes or None, view, False or the view's
   bound copy method, ...). */
static PyObject *cached_view(const FieldData *f, Holder *holder, const char *addr) {
    PyObject *dyn = holder->dyn;
    if (dyn == NULL || f->nkey == 0 || f->index >= PyList_Size(dyn))
        return NULL;
    PyObject *entry = PyList_GetItem(dyn, f->index);
    if (entry == NULL || !PyTuple_CheckExact(entry) || PyTuple_Size(entry) < 3)
        return NULL;
    PyObject *copy = PyTuple_GetItem(entry, 0);
    if (!PyBytes_CheckExact(copy) || PyBytes_Size(copy) != f->nkey * (Py_ssize_t)sizeof(void *))
        return NULL;
    const char *words = PyBytes_AsString(copy);
    for (int k = 0; k < f->nkey; k++)
        if (memcmp(addr + f->key[k], words + k * sizeof(void *), sizeof(void *)) != 0)
            return NULL;
    PyObject *fresh = PyTuple_GetItem(entry, 2);
    if (fresh != Py_False)            /* unallocated: a new array each read, by view.copy */
        return PyObject_CallNoArgs(fresh);
    PyObject *value = PyTuple_GetItem(entry, 1);
    Py_INCREF(value);
    return value;
}

static PyObject *field_get(PyObject *self, PyObject *obj, PyObject *type) {
    const FieldData *f = DATA(self);
    if (obj != NULL && obj != Py_None && f->kind != UNBOUND &&
            PyObject_TypeCheck(obj, (PyTypeObject *)f->owner)) {   /* its struct type */
        const char *addr = address(obj);
        if (addr != NULL) {
            if (f->kind != MOVING)
                return read_scalar(addr + f->offset, f->kind);
            PyObject *value = cached_view(f, (Holder *)obj, addr);
            if (value != NULL || PyErr_Occurred())
                return value;
        }
    }
    return property_get(self, obj, type);      /* the Python getter */
}

/* The struct class `owner` (a Holder type) that a field is bound to, or NULL and a
   TypeError: the C get reads only instances of it, whose memory has its layout. */
static PyObject *owner_of(PyObject *owner) {
    if (!PyType_Check(owner) || !PyType_IsSubtype((PyTypeObject *)owner, holder_type)) {
        PyErr_SetString(PyExc_TypeError, "a field binds to a struct class (a Holder type)");
        return NULL;
    }
    return owner;
}

static void set_owner(FieldData *f, PyObject *owner) {
    PyObject *old = f->owner;
    Py_INCREF(owner);
    f->owner = owner;
    Py_XDECREF(old);
}

/* _bind_scalar(owner, offset, kind, struct size): read `kind` at `offset` of instances of
   `owner` from now on. */
static PyObject *field_bind_scalar(PyObject *self, PyObject *args) {
    Py_ssize_t offset, size;
    int kind;
    PyObject *owner;
    if (!PyArg_ParseTuple(args, "Onin", &owner, &offset, &kind, &size) || !owner_of(owner))
        return NULL;
    static const int width[] = {0, 1, 1, 2, 2, 4, 4, 8, 8, 4, 8, 1};
    if (kind <= UNBOUND || kind >= MOVING || offset < 0 || offset + width[kind] > size) {
        PyErr_Format(PyExc_ValueError, "no scalar of kind %d at offset %zd of a %zd-byte struct",
                     kind, offset, size);
        return NULL;
    }
    FieldData *f = DATA(self);
    set_owner(f, owner);
    f->offset = offset;
    f->kind = kind;
    Py_RETURN_NONE;
}

/* _bind_moving(owner, index, key offsets, struct size): a moving array of instances of
   `owner`, whose cache entry is Holder.dyn[index], valid while the words at the key
   offsets are as copied. */
static PyObject *field_bind_moving(PyObject *self, PyObject *args) {
    Py_ssize_t index, size;
    PyObject *offsets, *owner;
    if (!PyArg_ParseTuple(args, "OnO!n", &owner, &index, &PyTuple_Type, &offsets, &size) ||
            !owner_of(owner))
        return NULL;
    Py_ssize_t n = PyTuple_Size(offsets);
    if (index < 0 || n < 1 || n > MAXKEY) {
        PyErr_Format(PyExc_ValueError, "a moving array needs an index >= 0 and 1 to %d key "
                     "words, not %zd and %zd", MAXKEY, index, n);
        return NULL;
    }
    Py_ssize_t key[MAXKEY];
    for (Py_ssize_t k = 0; k < n; k++) {
        key[k] = PyLong_AsSsize_t(PyTuple_GetItem(offsets, k));
        if (key[k] == -1 && PyErr_Occurred())
            return NULL;
        if (key[k] < 0 || key[k] + (Py_ssize_t)sizeof(void *) > size) {
            PyErr_Format(PyExc_ValueError, "key word at offset %zd is outside a %zd-byte struct",
                         key[k], size);
            return NULL;
        }
    }
    FieldData *f = DATA(self);
    set_owner(f, owner);
    memcpy(f->key, key, sizeof(key));
    f->nkey = (int)n;
    f->index = index;
    f->kind = MOVING;
    Py_RETURN_NONE;
}

/* The owner reference, for the GC: class -> its dict -> the field -> the class. */
static int field_traverse(PyObject *self, visitproc visit, void *arg) {
    Py_VISIT(DATA(self)->owner);
    Py_VISIT(Py_TYPE(self));      /* a heap type's instances visit their type */
    return property_traverse(self, visit, arg);
}

static int field_clear(PyObject *self) {
    DATA(self)->kind = UNBOUND;   /* unbound first: no C read without its owner */
    Py_CLEAR(DATA(self)->owner);
    return property_clear ? property_clear(self) : 0;
}

static void field_dealloc(PyObject *self) {
    PyTypeObject *type = Py_TYPE(self);
    PyObject_GC_UnTrack(self);
    DATA(self)->kind = UNBOUND;
    Py_CLEAR(DATA(self)->owner);
    PyObject_GC_Track(self);      /* property's dealloc untracks it again */
    property_dealloc(self);
    Py_DECREF(type);
}

static PyObject *field_kind(PyObject *self, void *closure) {
    return PyLong_FromLong(DATA(self)->kind);
}

static PyGetSetDef field_getset[] = {
    {"_kind", field_kind, NULL, "what the C get reads: 0 nothing (the Python getter), "
                                "1-11 a scalar type, 12 a moving array", NULL},
    {NULL}
};

static PyMethodDef field_methods[] = {
    {"_bind_scalar", field_bind_scalar, METH_VARARGS,
     "_bind_scalar(owner, offset, kind, struct_size): read the scalar of `kind` at "
     "`offset` of instances of the struct class `owner`."},
    {"_bind_moving", field_bind_moving, METH_VARARGS,
     "_bind_moving(owner, index, key_offsets, struct_size): for instances of `owner`, "
     "return Holder._dyn[index]'s view while the words at key_offsets are as its copy."},
    {NULL}
};

static PyType_Slot field_slots[] = {
    {Py_tp_doc, "A property that reads its field of an mjcffi struct in C (a scalar at its "
                "offset, or a cached view of moving memory); else its Python getter."},
    {Py_tp_descr_get, field_get},
    {Py_tp_traverse, field_traverse},
    {Py_tp_clear, field_clear},
    {Py_tp_dealloc, field_dealloc},
    {Py_tp_getset, field_getset},
    {Py_tp_methods, field_methods},
    {0, NULL}
};

static PyType_Spec field_spec = {
    "mjcffi._descriptors.Field", 0, 0,
    Py_TPFLAGS_DEFAULT | Py_TPFLAGS_BASETYPE | Py_TPFLAGS_HAVE_GC, field_slots
};

/* ------------------------------------------------------------------ module */

static struct PyModuleDef module_def = {
    PyModuleDef_HEAD_INIT, "mjcffi._descriptors",
    "The field descriptors of mjcffi's struct classes, in C (see mjcffi/_c/descriptors.c).",
    -1, NULL
};

PyMODINIT_FUNC PyInit__descriptors(void) {
    PyObject *module = PyModule_Create(&module_def);
    if (module == NULL)
        return NULL;
    str_locate = PyUnicode_InternFromString("_locate");
    PyObject *basicsize = PyObject_GetAttrString((PyObject *)&PyProperty_Type, "__basicsize__");
    if (str_locate == NULL || basicsize == NULL)
        goto fail;
    property_size = PyLong_AsSsize_t(basicsize);
    Py_DECREF(basicsize);
    if (property_size <= 0)
        goto fail;
    property_size = (property_size + 7) / 8 * 8;
    property_get = (descrgetfunc)PyType_GetSlot(&PyProperty_Type, Py_tp_descr_get);
    property_traverse = (traverseproc)PyType_GetSlot(&PyProperty_Type, Py_tp_traverse);
    property_clear = (inquiry)PyType_GetSlot(&PyProperty_Type, Py_tp_clear);
    property_dealloc = (destructor)PyType_GetSlot(&PyProperty_Type, Py_tp_dealloc);
    if (property_get == NULL || property_traverse == NULL || property_dealloc == NULL) {
        PyErr_SetString(PyExc_SystemError, "property has no get, traverse or dealloc slot");
        goto fail;
    }
    field_spec.basicsize = (int)(property_size + sizeof(FieldData));

    holder_type = (PyTypeObject *)PyType_FromSpec(&holder_spec);
    if (holder_type == NULL)
        goto fail;
    PyObject *bases = PyTuple_Pack(1, (PyObject *)&PyProperty_Type);
    if (bases == NULL)
        goto fail;
    field_type = (PyTypeObject *)PyType_FromSpecWithBases(&field_spec, bases);
    Py_DECREF(bases);
    if (field_type == NULL)
        goto fail;
    Py_INCREF((PyObject *)holder_type);
    Py_INCREF((PyObject *)field_type);
    if (PyModule_AddObject(module, "Holder", (PyObject *)holder_type) < 0 ||
            PyModule_AddObject(module, "Field", (PyObject *)field_type) < 0)
        goto fail;
    if (PyModule_AddIntConstant(module, "MOVING", MOVING) < 0)
        goto fail;
    return module;
fail:
    Py_DECREF(module);
    return NULL;
}
