"""Which names a robot file may give its robot and its parameters.

A robot's name becomes file and module names (`NAME/NAME.h`, `NAME.py`, `NAME_casadi.py`)
and the prefix of every C symbol; a symbolic parameter becomes a C struct field and local
variable and a Python keyword argument. So a name is refused when the generated code could
not compile or import with it, or would silently mean something else:

- robot names: C and Python keywords (`for.py` cannot be imported), C standard headers
  (`math/math.h` would hide `<math.h>`), Python standard modules and the modules the
  generated code imports (`numpy/numpy.py` would import itself);
- parameter names: C, C++ (the header may be included from C++) and Python keywords,
  Python builtins, `<math.h>` functions and macros, the generated code's own words
  (arguments, function names, temporaries `t0`, trig terms `c1`/`s23`/`c10_11`, joints `q1`,
  locals), names starting with `_` and names starting with the robot's prefix (`NAME_...`).

Python's keywords, builtins and standard modules are those of the interpreter running jacgen.

Joint names appear only in comments and documentation; the identifier pattern they must
match keeps them from ending a comment or a string.
"""

import builtins
import keyword
import re
import sys

C_KEYWORDS = frozenset("""
    auto break case char const continue default do double else enum extern float for goto if
    inline int long register restrict return short signed sizeof static struct switch typedef
    union unsigned void volatile while
""".split())
CPP_KEYWORDS = frozenset("""
    alignas alignof and and_eq asm bitand bitor bool catch char16_t char32_t char8_t class
    compl concept consteval constexpr constinit const_cast co_await co_return co_yield decltype
    delete dynamic_cast explicit export false friend mutable namespace new noexcept not not_eq
    nullptr operator or or_eq private protected public reinterpret_cast requires static_assert
    static_cast template this thread_local throw true try typeid typename using virtual wchar_t
    xor xor_eq
""".split())
C_STANDARD_HEADERS = frozenset("""
    assert complex ctype errno fenv float inttypes iso646 limits locale math setjmp signal
    stdalign stdarg stdatomic stdbool stddef stdint stdio stdlib stdnoreturn string tgmath
    threads time uchar wchar wctype
""".split())
_C_MATH_FUNCTIONS = """
    acos asin atan atan2 cos sin tan acosh asinh atanh cosh sinh tanh exp exp2 expm1 frexp
    ilogb ldexp log log10 log1p log2 logb modf scalbn scalbln cbrt fabs hypot pow sqrt erf erfc
    lgamma tgamma ceil floor nearbyint rint lrint llrint round lround llround trunc fmod
    remainder remquo copysign nan nextafter nexttoward fdim fmax fmin fma
""".split()
C_MATH_NAMES = frozenset(
    [name + suffix for name in _C_MATH_FUNCTIONS for suffix in ("", "f", "l")]
    + """
    fpclassify isfinite isinf isnan isnormal signbit isgreater isgreaterequal isless
    islessequal islessgreater isunordered float_t double_t math_errhandling HUGE_VAL HUGE_VALF
    HUGE_VALL INFINITY NAN MATH_ERRNO MATH_ERREXCEPT NULL errno EDOM ERANGE EILSEQ
    j0 j1 jn y0 y1 yn
    """.split()
)
PYTHON_KEYWORDS = frozenset(keyword.kwlist)
PYTHON_BUILTINS = frozenset(name for name in dir(builtins) if not name.startswith("_"))
# Modules the generated Python imports.
GENERATED_IMPORTS = frozenset({"numpy", "casadi", "math"})
# Words of the value grammar and of the generated code (contract §2, §3): arguments, functions
# and module constants, and the locals of generated functions that also take the parameters
# (tests/test_adversarial.py finds any the templates add; new locals had better start with
# '_', which no parameter name can).
GENERATED_NAMES = frozenset("""
    pi sqrt q p T J mu f damping target q0 max_iter tol q_dot mu_dot fk jacobian jacobian_tool
    task task_jacobian singularity_factors manipulability ik ik_branches jacobian_det
    velocity_ik ik_numeric fk_jacobian functions DOF TASK PARAMETERS MAX_IK_SOLUTIONS
    IK_NUMERIC_CONVERGED IK_NUMERIC_ITERATION_LIMIT IK_NUMERIC_STALLED VELOCITY_IK_OK
    VELOCITY_IK_SINGULAR VELOCITY_IK_NOT_FINITE status A d w x angles batch cost error least
    most revolute solutions step trial trial_cost branches count valid i j q_next q_start
    ik_numeric_step IK_NUMERIC_INVALID IK_NUMERIC_ITERATIONS active after better lighter retry
    worse fk_jacobian_dot jacobian_dot bias_acceleration task_jacobian_dot hessian Jd H a
    ik_nearest q_seed q_free weights in_limits IK_FREE_JOINT IK_NEAREST_OK IK_NEAREST_NO_SOLUTION
    IK_NEAREST_NOT_FINITE limits keep xp dtype device trig branches_q branches_valid
    branches_in_limits link_poses link_velocities velocity_ellipsoid condition_number
    manipulability_gradient velocity_ik_nullspace resolved_rate CHARACTERISTIC_LENGTH z gain
    target_rate U_v U_w s_v s_w V dw kappa
""".split())
# Every symbol name the generator makes up: a prefix and indices (`qb3_1`). This table is their
# one owner: the generator builds its symbols with `indexed` and `trig`, and a parameter may
# not take a name of this form.
GENERATED_PREFIXES = {
    "q": "joint positions q1..", "qd": "joint rates qd1..", "qs": "ik_numeric_step's q qs1..",
    "qn": "ik_nearest's seed qn1..", "qw": "ik_nearest's weights qw1..", "qb": "the ik_branches table qb0_0..",
    "vb": "its valid flags vb0..", "lb": "its in-limits flags lb0..", "ga": "the general 6R angles ga0..",
    "qg": "a general 6R solution qg1..", "T": "the entries of an ik target T00..",
    "mu": "the entries of a task target mu0..", "mu_dot": "task rates mu_dot0..",
    "qz": "null-space joint rates qz1..", "gain": "resolved_rate's gains gain0..",
    "c": "cos of a joint or a sum of joints c1.., c23..", "s": "sin of the same s1.., s23..",
    "t": "printed temporaries t0..", "w": "the state of a kernel (a repeated body) w0..",
}
INTERNAL_PREFIX = "_"  # the generator's own temporaries (`_n3`), never printed under that name
KERNEL_PREFIX = "jacgen_"  # the C's kernels and their state types (`jacgen_jacobi6_rows`)
_GENERATED_PATTERN = re.compile(
    "^(?:(?:" + "|".join(sorted(GENERATED_PREFIXES, key=len, reverse=True)) + r")[0-9]+(?:_[0-9]+)*"
    + "|" + INTERNAL_PREFIX + r".*|" + KERNEL_PREFIX + r"\w+|M_\w+|FP_\w+)$")  # and <math.h>'s M_PI, FP_NAN...


def indexed(prefix: str, *indices: int, separator: str = "_") -> str:
    """The generated symbol `prefix` of GENERATED_PREFIXES with its indices: q3, qb3_1 (T03 for
    a 4x4 matrix's entry, with no separator)."""
    if prefix not in GENERATED_PREFIXES:
        raise ValueError(f"{prefix!r} is not a generated prefix")
    return prefix + separator.join(map(str, indices))


def trig(joints: tuple[int, ...], dof: int) -> tuple[str, str]:
    """The names of the cos and sin of a sum of joint angles (0-based joints of a `dof`-joint
    robot): c2, s2 for joint 2; c23, s23 for joints 2 and 3. On a robot of ten joints or more the
    joints of a sum are separated, c1_2, so that the sum of joints 1 and 2 is not joint 12."""
    label = ("_" if dof > 9 else "").join(str(i + 1) for i in joints)
    return f"c{label}", f"s{label}"


def trig_joint(name: str) -> int | None:
    """The 0-based joint k of a name `trig((k,), dof)` gives, else None. (On a robot of nine
    joints or fewer, c23 reads as joint 23: ask only where no sum's symbol can be.)"""
    match = re.fullmatch(r"[cs]([1-9][0-9]*)", name)
    return None if match is None else int(match[1]) - 1


ROBOT_NAME_RULE = ("a robot name may not be a C or Python keyword, a C standard header or a "
                   "Python module name, since it names the generated files and modules")
PARAMETER_NAME_RULE = ("parameter names may not be C, C++ or Python keywords, Python builtins, "
                       "<math.h> names, names the generated code uses (q, p, fk, t0, c1, s1, q1, "
                       "T00, mu0, see jacgen/inputs/names.py), start with '_', 'jacgen_' or with "
                       "the robot's name and '_'")


def robot_name_problem(name: str) -> str | None:
    """Why `name` cannot name a robot (None when it can)."""
    if name in C_KEYWORDS or name in PYTHON_KEYWORDS:
        return "is a keyword"
    if name in C_STANDARD_HEADERS:
        return f"would hide the C header <{name}.h>"
    if name in GENERATED_IMPORTS or name in sys.stdlib_module_names:
        return f"would hide the Python module {name!r}"
    return None


# The words each language of the generated code reserves, by the reason given, keyed by the
# language (its backend, `emission/backends/NAME.py`). The languages are this table's keys
# (`backends.LANGUAGES`), so no language is generated without its reserved words refused.
C_RESERVED = {"is a keyword": C_KEYWORDS | CPP_KEYWORDS, "is a <math.h> name": C_MATH_NAMES}
PYTHON_RESERVED = {"is a keyword": PYTHON_KEYWORDS, "is a Python builtin": PYTHON_BUILTINS}
RESERVED = {"c": C_RESERVED, "python": PYTHON_RESERVED, "casadi": PYTHON_RESERVED, "report": {},
            "native": C_RESERVED}  # report: Markdown, no identifiers


def parameter_name_problem(name: str, robot_name: str) -> str | None:
    """Why `name` cannot name a parameter of robot `robot_name` (None when it can): a word a
    backend reserves, or one the generated code uses."""
    for reserved in RESERVED.values():
        for reason, words in reserved.items():
            if name in words:
                return reason
    if name in GENERATED_NAMES or name in GENERATED_IMPORTS or _GENERATED_PATTERN.fullmatch(name):
        return "is used by the generated code"
    if name.lower().startswith(robot_name + "_"):
        return f"starts with the robot's prefix {robot_name + '_'!r}"
    return None
