/* The CPython glue of a native module (templates/native/module.c.jinja): its functions'
 * arguments, one configuration straight through the C, batches through gufuncs whose loops copy
 * blocks of JACGEN_BLOCK rows into the kernels' layout and split them over threads, and the
 * module's initialisation. Defined before it by the module, after native_module.h and its own
 * header (native_kernels.h): JACGEN_FLAGS (the most flags of an output), JACGEN_DOF,
 * JACGEN_WORK_PER_THREAD (a batch is split over threads where each gets that many operations),
 * JACGEN_FUNCTIONS, the table jacgen_functions and jacgen_builds (each build's kernels, by
 * JACGEN_DOUBLE and JACGEN_FLOAT). */
static PyObject *jacgen_gufunc[JACGEN_FUNCTIONS];
static PyObject *jacgen_default[JACGEN_FUNCTIONS][JACGEN_OPERANDS][2]; /* arrays, per build */
static int jacgen_processors = 1;
static JACGEN_TLS int jacgen_threads_asked; /* 0: the usable processors */
static JACGEN_TLS int jacgen_scalar_asked; /* 1: the C function row by row, not the SIMD kernel */

static int jacgen_type(int kind, int build)
{
    return kind == JACGEN_BOOL ? NPY_BOOL : kind == JACGEN_INT ? NPY_INT32 : build == JACGEN_DOUBLE ? NPY_DOUBLE : NPY_FLOAT;
}

static size_t jacgen_packed_size(int kind, int build) /* of an element in a block */
{
    return kind != JACGEN_REAL ? sizeof(int) : build == JACGEN_DOUBLE ? sizeof(double) : sizeof(float);
}

/* -- Batches: the gufuncs' loop -- */

/* Between one row of an operand in numpy's memory (`strided`, with the core strides `core`)
 * and its packed copy in a block: gathered (inputs) or scattered (outputs; flags become npy_bool). */
static void jacgen_copy(const jacgen_operand *o, int build, char *strided, const npy_intp *core, char *packed, int gather)
{
    const size_t element = o->kind == JACGEN_BOOL ? sizeof(npy_bool) : jacgen_packed_size(o->kind, build);
    const size_t packed_size = jacgen_packed_size(o->kind, build);
    npy_intp n[3] = {1, 1, 1}, s[3] = {0, 0, 0}, i0, i1, i2, expected = (npy_intp)element;
    int d, whole = o->kind != JACGEN_BOOL;
    for (d = o->ndim - 1; d >= 0; d--) {
        n[3 - o->ndim + d] = o->shape[d];
        s[3 - o->ndim + d] = core[d];
        whole = whole && (core[d] == expected || o->shape[d] == 1);
        expected *= o->shape[d];
    }
    if (whole) {
        memcpy(gather ? packed : strided, gather ? strided : packed, (size_t)o->size * element);
        return;
    }
    for (i0 = 0; i0 < n[0]; i0++) {
        for (i1 = 0; i1 < n[1]; i1++) {
            for (i2 = 0; i2 < n[2]; i2++, packed += packed_size) {
                char *at = strided + i0 * s[0] + i1 * s[1] + i2 * s[2];
                if (o->kind == JACGEN_BOOL) {
                    *(npy_bool *)at = (npy_bool)(*(const int *)packed != 0);
                } else {
                    memcpy(gather ? packed : at, gather ? at : packed, element);
                }
            }
        }
    }
}

typedef struct {
    const jacgen_function *f;
    jacgen_kernel kernel;
    int build;
    char **args, *scratch;
    const npy_intp *steps, *core[JACGEN_OPERANDS];
    npy_intp begin, end;
} jacgen_job;

/* Where operand k of a block starts in a job's scratch (aligned), and the scratch's size. */
static size_t jacgen_offset(const jacgen_function *f, int build, int k)
{
    size_t offset = 0;
    int j;
    for (j = 0; j < k; j++) {
        size_t bytes = (size_t)(JACGEN_LANES * f->operand[j].pad) * jacgen_packed_size(f->operand[j].kind, build);
        offset += (bytes + JACGEN_ALIGN - 1) / JACGEN_ALIGN * JACGEN_ALIGN;
    }
    return offset;
}

/* Rows begin..end of a gufunc call, a block at a time. */
static void *jacgen_work(void *argument)
{
    jacgen_job *job = argument;
    const jacgen_function *f = job->f;
    const int operands = f->inputs + f->outputs;
    void *buffer[JACGEN_OPERANDS];
    npy_intp i;
    int k;
    long l, count;
    for (k = 0; k < operands; k++) {
        buffer[k] = job->scratch + jacgen_offset(f, job->build, k);
    }
    for (i = job->begin; i < job->end; i += JACGEN_BLOCK) {
        count = (long)(job->end - i < JACGEN_BLOCK ? job->end - i : JACGEN_BLOCK);
        for (k = 0; k < f->inputs; k++) { /* the lanes past the rows repeat the first: see JACGEN_LANES */
            const size_t row = (size_t)f->operand[k].pad * jacgen_packed_size(f->operand[k].kind, job->build);
            for (l = 0; l < JACGEN_LANES; l++) {
                jacgen_copy(&f->operand[k], job->build, job->args[k] + (i + (l < count ? l : 0)) * job->steps[k],
                            job->core[k], (char *)buffer[k] + (size_t)l * row, 1);
            }
        }
        job->kernel(buffer, count);
        for (k = f->inputs; k < operands; k++) {
            const size_t row = (size_t)f->operand[k].pad * jacgen_packed_size(f->operand[k].kind, job->build);
            for (l = 0; l < count; l++) {
                jacgen_copy(&f->operand[k], job->build, job->args[k] + (i + l) * job->steps[k], job->core[k],
                            (char *)buffer[k] + (size_t)l * row, 0);
            }
        }
    }
    return NULL;
}

/* A gufunc call: its rows split over the threads asked for (default: the usable processors),
 * each given at least JACGEN_WORK_PER_THREAD operations. The scratch of every thread is allocated
 * here, in the calling thread: a thread's first malloc would make it an arena of its own. */
static int jacgen_run(const jacgen_function *f, int build, char **args, const npy_intp *dimensions,
                      const npy_intp *steps)
{
    const npy_intp rows = dimensions[0];
    const jacgen_kernels *kernels = &jacgen_builds[build][f->kernel];
    const npy_intp least = (npy_intp)(JACGEN_WORK_PER_THREAD / f->operations) + 1;
    const npy_intp *core = steps + f->inputs + f->outputs;
    const size_t scratch = jacgen_offset(f, build, f->inputs + f->outputs);
    jacgen_job job[JACGEN_MAX_THREADS];
    int threads = jacgen_threads_asked > 0 ? jacgen_threads_asked : jacgen_processors, t, k;
    char *memory, *aligned;
    if (threads > JACGEN_MAX_THREADS) {
        threads = JACGEN_MAX_THREADS;
    }
    if (rows / least < threads) {
        threads = rows / least > 1 ? (int)(rows / least) : 1;
    }
    if ((memory = malloc((size_t)threads * scratch + JACGEN_ALIGN)) == NULL) {
        return -1;
    }
    aligned = memory + (JACGEN_ALIGN - (uintptr_t)memory % JACGEN_ALIGN) % JACGEN_ALIGN;
    for (t = 0; t < threads; t++) {
        const npy_intp *next = core;
        job[t].f = f;
        job[t].kernel = jacgen_scalar_asked ? kernels->scalar : kernels->simd;
        job[t].build = build;
        job[t].args = args;
        job[t].scratch = aligned + (size_t)t * scratch;
        job[t].steps = steps;
        for (k = 0; k < f->inputs + f->outputs; k++) {
            job[t].core[k] = next;
            next += f->operand[k].ndim;
        }
        job[t].begin = rows * t / threads;
        job[t].end = rows * (t + 1) / threads;
    }
#ifdef _WIN32
    for (t = 0; t < threads; t++) {
        jacgen_work(&job[t]);
    }
#else
    {
        pthread_t thread[JACGEN_MAX_THREADS];
        int started[JACGEN_MAX_THREADS] = {0};
        for (t = 1; t < threads; t++) {
            started[t] = pthread_create(&thread[t], NULL, jacgen_work, &job[t]) == 0;
            if (!started[t]) {
                jacgen_work(&job[t]);
            }
        }
        jacgen_work(&job[0]);
        for (t = 1; t < threads; t++) {
            if (started[t]) {
                pthread_join(thread[t], NULL);
            }
        }
    }
#endif
    free(memory);
    return 0;
}

/* A gufunc's loop. The C computes both sides of a select (a square root of a negative number
 * on the side not taken): its floating-point flags mean nothing, and are cleared, so that numpy
 * warns of nothing (NAME.py ignores them too). */
static void jacgen_loop(char **args, npy_intp const *dimensions, npy_intp const *steps, void *data, int build)
{
    const int failed = jacgen_run(data, build, args, dimensions, steps);
    feclearexcept(FE_ALL_EXCEPT);
    if (failed) {
        NPY_ALLOW_C_API_DEF
        NPY_ALLOW_C_API
        PyErr_NoMemory();
        NPY_DISABLE_C_API
    }
}

static void jacgen_loop_double(char **args, npy_intp const *dimensions, npy_intp const *steps, void *data)
{
    jacgen_loop(args, dimensions, steps, data, JACGEN_DOUBLE);
}

static void jacgen_loop_float(char **args, npy_intp const *dimensions, npy_intp const *steps, void *data)
{
    jacgen_loop(args, dimensions, steps, data, JACGEN_FLOAT);
}

/* float32 first: numpy takes the first loop its inputs cast to safely. */
static PyUFuncGenericFunction jacgen_loops[2] = {jacgen_loop_float, jacgen_loop_double};
static void *jacgen_loop_data[JACGEN_FUNCTIONS][2];
static char jacgen_loop_types[JACGEN_FUNCTIONS][2 * JACGEN_OPERANDS];

/* -- The functions: arguments as NAME.py takes them -- */

typedef struct {
    PyObject *value[JACGEN_OPERANDS]; /* the inputs given (borrowed), NULL for a default */
    PyObject *out;
    int threads, scalar, limits;
} jacgen_arguments;

static int jacgen_parse(const jacgen_function *f, PyObject *const *args, Py_ssize_t nargs, PyObject *kwnames,
                        jacgen_arguments *a, int takes_limits)
{
    Py_ssize_t i, keywords = kwnames == NULL ? 0 : PyTuple_GET_SIZE(kwnames);
    int k;
    memset(a, 0, sizeof *a);
    a->limits = 1;
    if (nargs > f->positional + takes_limits) {
        PyErr_Format(PyExc_TypeError, "%s() takes at most %d positional arguments (%zd given)", f->name,
                     f->positional + takes_limits, nargs);
        return -1;
    }
    if (nargs > f->positional && (a->limits = PyObject_IsTrue(args[f->positional])) < 0) { /* ik(T, limits) */
        return -1;
    }
    for (i = 0; i < nargs && i < f->positional; i++) {
        a->value[i] = args[i];
    }
    for (i = 0; i < keywords; i++) {
        PyObject *key = PyTuple_GET_ITEM(kwnames, i), *value = args[nargs + i];
        for (k = 0; k < f->inputs && PyUnicode_CompareWithASCIIString(key, f->operand[k].name) != 0; k++) {
        }
        if (k < f->inputs) {
            if (a->value[k] != NULL) {
                PyErr_Format(PyExc_TypeError, "%s() got multiple values for argument '%s'", f->name, f->operand[k].name);
                return -1;
            }
            a->value[k] = value;
        } else if (PyUnicode_CompareWithASCIIString(key, "out") == 0 && !takes_limits) {
            a->out = value == Py_None ? NULL : value;
        } else if (PyUnicode_CompareWithASCIIString(key, "threads") == 0) {
            long threads = value == Py_None ? 0 : PyLong_AsLong(value);
            if (threads == -1 && PyErr_Occurred()) {
                return -1;
            }
            if (value != Py_None && threads < 1) {
                PyErr_Format(PyExc_ValueError, "%s(): threads must be None or at least 1, got %ld", f->name, threads);
                return -1;
            }
            a->threads = threads > JACGEN_MAX_THREADS ? JACGEN_MAX_THREADS : (int)threads;
        } else if (PyUnicode_CompareWithASCIIString(key, "simd") == 0) {
            if ((a->scalar = PyObject_Not(value)) < 0) {
                return -1;
            }
        } else if (takes_limits && PyUnicode_CompareWithASCIIString(key, "limits") == 0) {
            if ((a->limits = PyObject_IsTrue(value)) < 0) {
                return -1;
            }
        } else {
            PyErr_Format(PyExc_TypeError, "%s() got an unexpected keyword argument '%U'", f->name, key);
            return -1;
        }
    }
    for (k = 0; k < f->inputs; k++) {
        if (a->value[k] == NULL && f->operand[k].default_value == NULL) {
            PyErr_Format(PyExc_TypeError, "%s() missing required argument '%s'", f->name, f->operand[k].name);
            return -1;
        }
    }
    return 0;
}

/* float32 when every array among the real inputs is float32 (or float16), else float64, as
 * NAME.py: lists and numbers follow the arrays. */
static int jacgen_build(const jacgen_function *f, const jacgen_arguments *a)
{
    int k, given = 0, floats = 0;
    for (k = 0; k < f->inputs; k++) {
        PyObject *value = a->value[k];
        if (value != NULL && f->operand[k].kind == JACGEN_REAL && (PyArray_Check(value) || PyArray_IsScalar(value, Generic))) {
            PyArray_Descr *descr = PyArray_Check(value) ? PyArray_DESCR((PyArrayObject *)value) : PyArray_DescrFromScalar(value);
            given++;
            floats += descr->type_num == NPY_FLOAT || descr->type_num == NPY_HALF;
            if (!PyArray_Check(value)) {
                Py_DECREF(descr);
            }
        }
    }
    return given > 0 && floats == given ? JACGEN_FLOAT : JACGEN_DOUBLE;
}

/* A list or tuple of Python numbers (nested as the operand's shape) into `real` and `single`;
 * 0 where it is not that (numpy then converts it). */
static int jacgen_listed(const jacgen_operand *o, PyObject *value, int d, npy_intp *at, double *real, float *single)
{
    Py_ssize_t i, n;
    if (!(PyList_CheckExact(value) || PyTuple_CheckExact(value)) || (n = PySequence_Fast_GET_SIZE(value)) != o->shape[d]) {
        return 0;
    }
    for (i = 0; i < n; i++) {
        PyObject *item = PySequence_Fast_GET_ITEM(value, i);
        if (d + 1 < o->ndim) {
            if (!jacgen_listed(o, item, d + 1, at, real, single)) {
                return 0;
            }
            continue;
        }
        if (PyFloat_CheckExact(item)) {
            real[*at] = PyFloat_AS_DOUBLE(item);
        } else if (PyLong_CheckExact(item)) {
            real[*at] = PyLong_AsDouble(item);
            if (real[*at] == -1.0 && PyErr_Occurred()) {
                PyErr_Clear();
                return 0;
            }
        } else {
            return 0;
        }
        single[*at] = (float)real[*at];
        ++*at;
    }
    return 1;
}

/* The input as the C takes it for one configuration, without a copy (`real`/`integer` hold a
 * number, or a short list's numbers); NULL where the gufunc must take it. */
static void *jacgen_direct(const jacgen_operand *o, PyObject *value, int build, double *real, float *single, int *integer)
{
    if (o->kind == JACGEN_INT) {
        long number;
        if (!PyLong_CheckExact(value)) {
            return NULL;
        }
        number = PyLong_AsLong(value);
        if ((number == -1 && PyErr_Occurred()) || number < INT32_MIN || number > INT32_MAX) {
            PyErr_Clear();
            return NULL;
        }
        *integer = (int)number;
        return integer;
    }
    if (o->ndim == 0 && (PyFloat_Check(value) || PyLong_Check(value) || PyArray_IsScalar(value, Float))) {
        double number = PyArray_IsScalar(value, Float) ? (double)PyArrayScalar_VAL(value, Float) : PyFloat_AsDouble(value);
        if (number == -1.0 && PyErr_Occurred()) {
            PyErr_Clear();
            return NULL;
        }
        *real = number;
        *single = (float)number;
        return build == JACGEN_DOUBLE ? (void *)real : (void *)single;
    }
    if (o->kind == JACGEN_REAL && o->ndim > 0 && o->size <= JACGEN_HELD && (PyList_CheckExact(value) || PyTuple_CheckExact(value))) {
        npy_intp at = 0;
        return !jacgen_listed(o, value, 0, &at, real, single) ? NULL : build == JACGEN_DOUBLE ? (void *)real : (void *)single;
    }
    if (PyArray_CheckExact(value)) {
        PyArrayObject *array = (PyArrayObject *)value;
        int d;
        if (PyArray_TYPE(array) != jacgen_type(JACGEN_REAL, build) || PyArray_NDIM(array) != o->ndim
            || !PyArray_ISCARRAY_RO(array) || PyArray_ISBYTESWAPPED(array)) {
            return NULL;
        }
        for (d = 0; d < o->ndim; d++) {
            if (PyArray_DIM(array, d) != o->shape[d]) {
                return NULL;
            }
        }
        return PyArray_DATA(array);
    }
    return NULL;
}

/* The inputs of one configuration, each as the C takes it without a copy (`held` keeps the
 * numbers); 0 where the gufunc must take them. */
static int jacgen_direct_inputs(const jacgen_function *f, int build, const jacgen_arguments *a, void **buffer,
                                double (*real)[JACGEN_HELD], float (*single)[JACGEN_HELD], int *integer)
{
    int k;
    if (a->out != NULL) {
        return 0;
    }
    for (k = 0; k < f->inputs; k++) {
        PyObject *value = a->value[k] != NULL ? a->value[k] : jacgen_default[f - jacgen_functions][k][build];
        if ((buffer[k] = jacgen_direct(&f->operand[k], value, build, real[k], single[k], &integer[k])) == NULL) {
            return 0;
        }
    }
    return 1;
}

/* One configuration in contiguous arrays: the C function, called once. NULL (no error set)
 * where the arguments are not that. */
static PyObject *jacgen_one(const jacgen_function *f, int build, const jacgen_arguments *a)
{
    const int operands = f->inputs + f->outputs;
    void *buffer[JACGEN_OPERANDS];
    double real[JACGEN_OPERANDS][JACGEN_HELD];
    float single[JACGEN_OPERANDS][JACGEN_HELD];
    int integer[JACGEN_OPERANDS], flags[JACGEN_OPERANDS][JACGEN_FLAGS];
    PyObject *result[JACGEN_OPERANDS], *tuple;
    int k, j;
    if (!jacgen_direct_inputs(f, build, a, buffer, real, single, integer)) {
        return NULL;
    }
    for (k = f->inputs; k < operands; k++) {
        const jacgen_operand *o = &f->operand[k];
        result[k] = PyArray_SimpleNew(o->ndim, (npy_intp *)o->shape, jacgen_type(o->kind, build));
        if (result[k] == NULL) {
            while (--k >= f->inputs) {
                Py_DECREF(result[k]);
            }
            return NULL;
        }
        buffer[k] = o->kind == JACGEN_BOOL ? (void *)flags[k] : PyArray_DATA((PyArrayObject *)result[k]);
    }
    jacgen_builds[build][f->kernel].scalar(buffer, 1);
    for (k = f->inputs; k < operands; k++) {
        if (f->operand[k].kind == JACGEN_BOOL) {
            npy_bool *to = PyArray_DATA((PyArrayObject *)result[k]);
            for (j = 0; j < f->operand[k].size; j++) {
                to[j] = (npy_bool)(flags[k][j] != 0);
            }
        }
    }
    if (f->outputs == 1) {
        return result[f->inputs];
    }
    tuple = PyTuple_New(f->outputs);
    if (tuple == NULL) {
        for (k = f->inputs; k < operands; k++) {
            Py_DECREF(result[k]);
        }
        return NULL;
    }
    for (k = f->inputs; k < operands; k++) {
        PyTuple_SET_ITEM(tuple, k - f->inputs, result[k]);
    }
    return tuple;
}

/* Any arguments: converted to the build's type and passed to the gufunc. */
static PyObject *jacgen_many(const jacgen_function *f, int build, const jacgen_arguments *a)
{
    PyObject *inputs = PyTuple_New(f->inputs), *keywords = NULL, *result = NULL;
    int k, threads = jacgen_threads_asked, scalar = jacgen_scalar_asked;
    if (inputs == NULL) {
        return NULL;
    }
    for (k = 0; k < f->inputs; k++) {
        PyObject *value = a->value[k] != NULL ? a->value[k] : jacgen_default[f - jacgen_functions][k][build];
        PyObject *array = PyArray_FromAny(value, PyArray_DescrFromType(jacgen_type(f->operand[k].kind, build)), 0, 0,
                                          NPY_ARRAY_ALIGNED | NPY_ARRAY_FORCECAST, NULL);
        if (array == NULL) {
            Py_DECREF(inputs);
            return NULL;
        }
        PyTuple_SET_ITEM(inputs, k, array);
    }
    if (a->out != NULL && (keywords = Py_BuildValue("{s:O}", "out", a->out)) == NULL) {
        Py_DECREF(inputs);
        return NULL;
    }
    jacgen_threads_asked = a->threads;
    jacgen_scalar_asked = a->scalar;
    result = PyObject_Call(jacgen_gufunc[f->kernel], inputs, keywords);
    jacgen_threads_asked = threads;
    jacgen_scalar_asked = scalar;
    Py_DECREF(inputs);
    Py_XDECREF(keywords);
    return result;
}

/* A number given for an input that takes one for each component (`scalar_allowed`) becomes the
 * list of them, held in `lists` for the caller to release. */
static int jacgen_spread_scalars(const jacgen_function *f, jacgen_arguments *a, PyObject **lists)
{
    int k;
    Py_ssize_t i;
    for (k = 0; k < f->inputs; k++) {
        PyObject *value = a->value[k];
        lists[k] = NULL;
        if (!f->operand[k].scalar_allowed || value == NULL
            || !(PyFloat_Check(value) || PyLong_Check(value) || PyArray_IsScalar(value, Generic)
                 || (PyArray_Check(value) && PyArray_NDIM((PyArrayObject *)value) == 0))) {
            continue;
        }
        if ((lists[k] = PyList_New(f->operand[k].size)) == NULL) {
            return -1;
        }
        for (i = 0; i < f->operand[k].size; i++) {
            PyList_SET_ITEM(lists[k], i, Py_NewRef(value));
        }
        a->value[k] = lists[k];
    }
    return 0;
}

static PyObject *jacgen_call(const jacgen_function *f, PyObject *const *args, Py_ssize_t nargs, PyObject *kwnames)
{
    jacgen_arguments a;
    PyObject *result = NULL, *lists[JACGEN_OPERANDS] = {NULL};
    int build, k;
    if (jacgen_parse(f, args, nargs, kwnames, &a, 0) != 0) {
        return NULL;
    }
    if (jacgen_spread_scalars(f, &a, lists) == 0) {
        build = jacgen_build(f, &a);
        result = jacgen_one(f, build, &a);
        result = result != NULL || PyErr_Occurred() ? result : jacgen_many(f, build, &a);
    }
    for (k = 0; k < f->inputs; k++) {
        Py_XDECREF(lists[k]);
    }
    return result;
}

/* ik of one target: the valid (and in_limits) rows of ik_branches as (k, DOF), straight from
 * the C's arrays. NULL (no error set) where the arguments are not one target. */
static PyObject *jacgen_ik_one(const jacgen_function *f, int build, const jacgen_arguments *a)
{
    const jacgen_operand *q = &f->operand[f->inputs];
    const size_t element = jacgen_packed_size(JACGEN_REAL, build), row = (size_t)q->shape[1] * element;
    void *buffer[JACGEN_OPERANDS];
    double real[JACGEN_OPERANDS][JACGEN_HELD], solutions[JACGEN_FLAGS * JACGEN_DOF];
    float single[JACGEN_OPERANDS][JACGEN_HELD];
    int integer[JACGEN_OPERANDS], valid[JACGEN_FLAGS], in_limits[JACGEN_FLAGS], i, kept = 0;
    npy_intp shape[2];
    PyObject *result;
    if (!jacgen_direct_inputs(f, build, a, buffer, real, single, integer)) {
        return NULL;
    }
    buffer[f->inputs] = solutions;
    buffer[f->inputs + 1] = valid;
    buffer[f->inputs + 2] = in_limits;
    jacgen_builds[build][f->kernel].scalar(buffer, 1);
    for (i = 0; i < q->shape[0]; i++) {
        kept += valid[i] && (in_limits[i] || !a->limits);
    }
    shape[0] = kept;
    shape[1] = q->shape[1];
    if ((result = PyArray_SimpleNew(2, shape, jacgen_type(JACGEN_REAL, build))) == NULL) {
        return NULL;
    }
    for (i = 0, kept = 0; i < q->shape[0]; i++) {
        if (valid[i] && (in_limits[i] || !a->limits)) {
            memcpy((char *)PyArray_DATA((PyArrayObject *)result) + (size_t)kept++ * row, (char *)solutions + (size_t)i * row, row);
        }
    }
    return result;
}

/* ik: the rows of ik_branches that are valid (and in_limits unless limits is False); one
 * target gives them as (k, DOF), a batch gives (q, keep). */
static PyObject *jacgen_ik(const jacgen_function *f, PyObject *const *args, Py_ssize_t nargs, PyObject *kwnames)
{
    jacgen_arguments a;
    PyObject *branches, *q, *valid, *in_limits, *keep, *result;
    int build;
    if (jacgen_parse(f, args, nargs, kwnames, &a, 1) != 0) {
        return NULL;
    }
    build = jacgen_build(f, &a);
    if ((result = jacgen_ik_one(f, build, &a)) != NULL || PyErr_Occurred()) {
        return result;
    }
    if ((branches = jacgen_many(f, build, &a)) == NULL) {
        return NULL;
    }
    q = PyTuple_GET_ITEM(branches, 0);
    valid = PyTuple_GET_ITEM(branches, 1);
    in_limits = PyTuple_GET_ITEM(branches, 2);
    keep = a.limits ? PyNumber_And(valid, in_limits) : Py_NewRef(valid);
    if (keep == NULL) {
        Py_DECREF(branches);
        return NULL;
    }
    result = PyArray_NDIM((PyArrayObject *)keep) == 1 ? PyObject_GetItem(q, keep) : PyTuple_Pack(2, q, keep);
    Py_DECREF(keep);
    Py_DECREF(branches);
    return result;
}

/* The value of a Python expression (the module's constants and the functions' defaults). */
static PyObject *jacgen_evaluate(const char *expression)
{
    PyObject *names = Py_BuildValue("{s:O,s:i}", "__builtins__", PyEval_GetBuiltins(), "DOF", JACGEN_DOF), *value;
    if (names == NULL) {
        return NULL;
    }
    value = PyRun_String(expression, Py_eval_input, names, names);
    Py_DECREF(names);
    return value;
}

/* The processors this process may run on (os.sched_getaffinity where there is one). */
static int jacgen_usable_processors(void)
{
    PyObject *count = jacgen_evaluate("len(__import__('os').sched_getaffinity(0)) if hasattr(__import__('os'), "
                                      "'sched_getaffinity') else (__import__('os').cpu_count() or 1)");
    long value = count == NULL ? 1 : PyLong_AsLong(count);
    Py_XDECREF(count);
    PyErr_Clear();
    return value < 1 ? 1 : value > JACGEN_MAX_THREADS ? JACGEN_MAX_THREADS : (int)value;
}

/* What the batches run: the widest vector code the processor takes, or "scalar". */
static const char *jacgen_simd(void)
{
#if defined(JACGEN_SIMD) && defined(JACGEN_CLONES)
    __builtin_cpu_init();
    return __builtin_cpu_supports("avx512f") ? "avx512f" : __builtin_cpu_supports("avx2") ? "avx2" : "baseline";
#elif defined(JACGEN_SIMD) && defined(JACGEN_INSTRUCTION_SET)
    return JACGEN_INSTRUCTION_SET; /* the one set setup.py compiled for */
#elif defined(JACGEN_SIMD)
    return "baseline";
#else
    return "scalar";
#endif
}

/* The module of `definition`, with its `count` constants (name, Python expression), SIMD, and
 * its gufuncs as the module NAME.gufuncs, NAME the module's full name (jacgen.arm's modules
 * live in a package). */
static PyObject *jacgen_init(struct PyModuleDef *definition, const char *const constants[][2], int count)
{
    PyObject *module, *name, *gufuncs = NULL, *gufuncs_name = NULL;
    int i, k, build;
    import_array();
    import_umath();
    module = PyModule_Create(definition);
    name = module == NULL ? NULL : PyModule_GetNameObject(module);
    gufuncs_name = name == NULL ? NULL : PyUnicode_FromFormat("%U.gufuncs", name);
    Py_XDECREF(name);
    gufuncs = gufuncs_name == NULL ? NULL : PyModule_NewObject(gufuncs_name);
    /* in sys.modules too: numpy pickles a ufunc by the module that holds it (dask sends them) */
    if (gufuncs == NULL || PyDict_SetItem(PyImport_GetModuleDict(), gufuncs_name, gufuncs) != 0
        || PyModule_AddObject(module, "gufuncs", gufuncs) != 0) {
        Py_XDECREF(gufuncs_name);
        goto fail;
    }
    Py_DECREF(gufuncs_name);
    for (i = 0; i < count; i++) {
        PyObject *value = jacgen_evaluate(constants[i][1]);
        if (value == NULL || PyModule_AddObject(module, constants[i][0], value) != 0) {
            Py_XDECREF(value);
            goto fail;
        }
    }
    if (PyModule_AddStringConstant(module, "SIMD", jacgen_simd()) != 0) {
        goto fail;
    }
    for (i = 0; i < JACGEN_FUNCTIONS; i++) {
        const jacgen_function *f = &jacgen_functions[i];
        for (k = 0; k < f->inputs; k++) {
            PyObject *value;
            if (f->operand[k].default_value == NULL) {
                continue;
            }
            if ((value = jacgen_evaluate(f->operand[k].default_value)) == NULL) {
                goto fail;
            }
            for (build = 0; build < 2; build++) {
                jacgen_default[i][k][build] = PyArray_FromAny(
                    value, PyArray_DescrFromType(jacgen_type(f->operand[k].kind, build)), 0, 0, NPY_ARRAY_CARRAY | NPY_ARRAY_FORCECAST, NULL);
                if (jacgen_default[i][k][build] == NULL) {
                    Py_DECREF(value);
                    goto fail;
                }
            }
            Py_DECREF(value);
        }
        if (f->kernel != i) {
            continue; /* ik: ik_branches' gufunc */
        }
        for (build = 0; build < 2; build++) {
            for (k = 0; k < f->inputs + f->outputs; k++) {
                jacgen_loop_types[i][build * (f->inputs + f->outputs) + k] =
                    (char)jacgen_type(f->operand[k].kind, build == 0 ? JACGEN_FLOAT : JACGEN_DOUBLE);
            }
            jacgen_loop_data[i][build] = (void *)f;
        }
        jacgen_gufunc[i] = PyUFunc_FromFuncAndDataAndSignature(
            jacgen_loops, jacgen_loop_data[i], jacgen_loop_types[i], 2, f->inputs, f->outputs, PyUFunc_None, f->name,
            f->doc, 0, f->signature);
        if (jacgen_gufunc[i] == NULL || PyModule_AddObjectRef(gufuncs, f->name, jacgen_gufunc[i]) != 0) {
            goto fail;
        }
    }
    jacgen_processors = jacgen_usable_processors();
    return module;
fail:
    Py_XDECREF(module);
    return NULL;
}
