/* Rows a kernel computes at once: a multiple of every vector width (16 floats in AVX-512), and
 * enough rows to pay a kernel's setup once for many (10^6 ur5 ik on two cores: 3.9 M poses per
 * second with 16 rows, 6.8 M with 64, 7.4 M with 128). */
#define JACGEN_BLOCK 64
/* Lanes a SIMD kernel computes: the block and one vector of the widest (16 floats) more, which
 * repeat the block's first row. gcc peels a loop's last vector iteration into scalar or
 * narrower code where a row's padding would be read past the end ("peeling for gaps"); the
 * peeled lanes are then these, and every row of the block runs the same vector code, whatever
 * its place in the batch. */
#define JACGEN_LANES (JACGEN_BLOCK + 16)

/* A kernel runs one function on a block: buffers[k] holds operand k (inputs, then outputs) of
 * every row, rows `pad` elements apart, reals of the build, int for statuses, flags and
 * max_iter. A SIMD kernel computes all JACGEN_LANES rows, so that every row of the block runs
 * the same vector code; the scalar kernel (the C function row by row) computes the first
 * `count`. */
typedef void (*jacgen_kernel)(void *const *buffers, long count);

/* Each function's kernels, in the order of the module's table: the SIMD one (the scalar one
 * where the platform has no vector math or the function is not a straight line) and the
 * scalar one (the C function called row by row). */
typedef struct {
    jacgen_kernel simd, scalar;
} jacgen_kernels;
