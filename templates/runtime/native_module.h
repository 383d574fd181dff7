/* The native module's headers and types (templates/native/module.c.jinja, native_module.c).
 * Defined before it by the module: JACGEN_OPERANDS, the most operands of a function. */
#define PY_SSIZE_T_CLEAN
#include <Python.h>
#define NPY_NO_DEPRECATED_API NPY_1_7_API_VERSION
#include <numpy/arrayobject.h>
#include <numpy/arrayscalars.h>
#include <numpy/ufuncobject.h>
#include <fenv.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#ifndef _WIN32
#include <pthread.h>
#endif

#if defined(_MSC_VER)
#define JACGEN_TLS __declspec(thread)
#else
#define JACGEN_TLS _Thread_local
#endif

/* Statuses and flags are C ints, numpy int32. */
typedef char jacgen_int_is_int32[sizeof(int) == sizeof(npy_int32) ? 1 : -1];

enum { JACGEN_DOUBLE, JACGEN_FLOAT };
enum { JACGEN_REAL, JACGEN_INT, JACGEN_BOOL };
#define JACGEN_MAX_THREADS 256
#define JACGEN_HELD 32 /* a list of at most this many numbers is read straight into the C's arguments */
#define JACGEN_ALIGN 64

typedef struct {
    const char *name;
    int kind, ndim;
    npy_intp shape[3];
    npy_intp size, pad; /* elements, and the distance of two rows in a block */
    const char *default_value; /* a Python expression; NULL: required */
    int scalar_allowed; /* a number stands for each component (resolved_rate's gain) */
} jacgen_operand;

typedef struct {
    const char *name, *doc, *signature;
    int positional, inputs, outputs; /* inputs: the arguments, then the parameters (keyword only) */
    int kernel; /* the index of its kernels and gufunc (ik: those of ik_branches) */
    double operations; /* per row: a batch is split over threads where it pays */
    jacgen_operand operand[JACGEN_OPERANDS]; /* inputs, then outputs */
} jacgen_function;
