"""Writes the peers' generated code for the same-run benchmark
(`peers/benches/peers.rs`): the collision maps of the paper's §3.1 and §3.2
balls and of the n-link chain family (n = 1..8), as SymForce (C++) and
CasADi (C) generate them.

Run from the repository root with SymForce 0.12 and CasADi 3.8 installed:

    python3 peers/generate.py

It writes peers/generated/ (not committed). Each map takes the model's
parameters and state as plain arguments, as a user of those tools would
call it, and recomputes everything from them on every call.

The chain's map is v+ = v - 2 y (B v)/(B y) with G y = B^T, G = L D L^T
eliminated symbolically (no pivoting, no simplification; the tools share
common subexpressions). The balls' maps are (I - 2P) v with
P = G^-1 B^T (B G^-1 B^T)^-1 B simplified entry by entry (sympy), B's rows
reduced to a basis of their span first.
"""

import os
import sys
import time

import symforce

symforce.set_epsilon_to_zero()
import casadi  # noqa: E402
import sympy  # noqa: E402
import symforce.symbolic as sf  # noqa: E402
from symforce import codegen  # noqa: E402

OUT = os.path.join(os.path.dirname(os.path.abspath(__file__)), "generated")
CHAINS = range(1, 9)


def ldl_solve(g, b, n):
    """y with G y = b by G = L D L^T, entry by entry, in whatever algebra
    the entries are (SymForce or CasADi symbols)."""
    lower = [[None] * n for _ in range(n)]
    d = [None] * n
    for j in range(n):
        acc = g[j][j]
        for k in range(j):
            acc = acc - lower[j][k] * lower[j][k] * d[k]
        d[j] = acc
        for i in range(j + 1, n):
            acc = g[i][j]
            for k in range(j):
                acc = acc - lower[i][k] * lower[j][k] * d[k]
            lower[i][j] = acc / d[j]
    z = list(b)
    for i in range(n):
        for k in range(i):
            z[i] = z[i] - lower[i][k] * z[k]
    y = [z[i] / d[i] for i in range(n)]
    for i in reversed(range(n)):
        for k in range(i + 1, n):
            y[i] = y[i] - lower[k][i] * y[k]
    return y


def chain_map(n, q, v, m, l, sin, cos):
    """v+ of the n-link chain (models/chain_N.toml) hitting the floor."""
    s = [sin(x) for x in q]
    c = [cos(x) for x in q]
    g = [[None] * n for _ in range(n)]
    for i in range(n):
        for j in range(n):
            mass = m[max(i, j)]
            for k in range(max(i, j) + 1, n):
                mass = mass + m[k]
            g[i][j] = mass * l[i] * l[j] * (c[i] * c[j] + s[i] * s[j])
    # f = h - sum l_k cos q_k: its gradient, B's one row.
    b = [l[k] * s[k] for k in range(n)]
    y = ldl_solve(g, b, n)
    bv = b[0] * v[0]
    by = b[0] * y[0]
    for k in range(1, n):
        bv = bv + b[k] * v[k]
        by = by + b[k] * y[k]
    lam = 2 * bv / by
    return [v[k] - lam * y[k] for k in range(n)]


def reflection(gdiag, rows):
    """I - 2P for G = diag(gdiag) and B's rows (sympy), simplified."""
    b = sympy.Matrix(rows)
    basis = b.T.columnspace()
    b = sympy.Matrix.hstack(*basis).T
    ginv = sympy.diag(*[1 / x for x in gdiag])
    p = ginv * b.T * (b * ginv * b.T).inv() * b
    return sympy.simplify(sympy.eye(len(gdiag)) - 2 * p)


def ball_wall():
    m, r, j = sympy.symbols("m r J", positive=True)
    v1, v2, w1, w2, w3 = sympy.symbols("v1 v2 w1 w2 w3")
    vel = [v1, v2, w1, w2, w3]
    rows = [
        [sympy.diff(e, x) for x in vel]
        for e in [v1, v1 - r * w2, v2 + r * w1, v2 - r * w3, r * w2]
    ]
    return reflection([m, m, j, j, j], rows), (m, r, j)


def ball_floor():
    m, r, j = sympy.symbols("m r J", positive=True)
    vel = sympy.symbols("v1 v2 v3 w1 w2 w3")
    v1, v2, v3, w1, w2, w3 = vel
    rows = [[sympy.diff(e, x) for x in vel] for e in [v3, v1 - r * w2, v2 + r * w1]]
    return reflection([m, m, m, j, j, j], rows), (m, r, j)


def write(path, text):
    with open(path, "w") as fh:
        fh.write(text)


def symforce_function(f, name):
    """Generates SymForce's C++ for f into OUT; returns its C++ name."""
    f.__name__ = name
    cg = codegen.Codegen.function(f, config=codegen.CppConfig(), name=name)
    cg.generate_function(output_dir=OUT, skip_directory_nesting=True)
    return "".join(p.capitalize() for p in name.split("_"))


def casadi_function(name, inputs, outputs):
    """Generates CasADi's C (with its header) for the SX outputs into OUT."""
    casadi.Function(name, inputs, [casadi.vertcat(*outputs)]).generate(
        f"{name}.c", {"with_header": True}
    )
    for ext in ("c", "h"):
        os.replace(f"{name}.{ext}", os.path.join(OUT, f"{name}.{ext}"))


def wrapper(name, cls, params, arrays, size):
    """The extern "C" wrapper of SymForce's function: scalar parameters,
    then arrays of `size` values, then the output array."""
    args = [f"double {p}" for p in params] + [f"const double* {a}" for a in arrays]
    maps = ", ".join(f"{a}{a}({a})" for a in arrays)
    call = ", ".join(list(params) + [f"{a}{a}" for a in arrays])
    return (
        f'#include "{name}.h"\n'
        f'extern "C" void sf_{name}({", ".join(args)}, double* out) {{\n'
        f"  using V = Eigen::Matrix<double, {size}, 1>;\n"
        f"  const Eigen::Map<const V> {maps};\n"
        f"  Eigen::Map<V> o(out);\n"
        f"  o = sym::{cls}<double>({call});\n}}"
    )


def main():
    os.makedirs(OUT, exist_ok=True)
    wrappers = ["#include <cmath>", "#include <Eigen/Core>"]
    names = []
    times = {}

    # §3.1 and §3.2: P simplified once (sympy), then each tool's code.
    for name, derive, size in [("ball_wall", ball_wall, 5), ("ball_floor", ball_floor, 6)]:
        start = time.perf_counter()
        matrix, _ = derive()
        times[f"sympy {name} (P simplified)"] = time.perf_counter() - start
        start = time.perf_counter()
        syms = {x: sf.Symbol(x) for x in ("m", "r", "J")}
        mm = sf.Matrix(size, size, [sf.sympify(str(x)) for x in matrix])

        def f(m: sf.Scalar, r: sf.Scalar, J: sf.Scalar, v: sf.Matrix(size, 1)):  # type: ignore
            return mm.subs({syms["m"]: m, syms["r"]: r, syms["J"]: J}) * v

        cls = symforce_function(f, name)
        times[f"symforce {name}"] = time.perf_counter() - start
        wrappers.append(wrapper(name, cls, ["m", "r", "J"], ["v"], size))
        start = time.perf_counter()
        mc, rc, jc = casadi.SX.sym("m"), casadi.SX.sym("r"), casadi.SX.sym("J")
        vc = casadi.SX.sym("v", size)
        env = {"m": mc, "r": rc, "J": jc, "sqrt": casadi.sqrt}
        out = []
        for i in range(size):
            acc = casadi.SX(0)
            for k in range(size):
                if matrix[i, k] != 0:
                    acc = acc + eval(sympy.pycode(matrix[i, k]).replace("math.", ""), env) * vc[k]
            out.append(acc)
        casadi_function(f"ca_{name}", [mc, rc, jc, vc], out)
        times[f"casadi {name}"] = time.perf_counter() - start
        names.append(name)

    # The chains: the elimination, unsimplified, in each tool.
    for n in CHAINS:
        name = f"chain_{n}"
        start = time.perf_counter()

        def f(q: sf.Matrix(n, 1), v: sf.Matrix(n, 1), m: sf.Matrix(n, 1), l: sf.Matrix(n, 1)):  # type: ignore
            return sf.Matrix(n, 1, chain_map(n, list(q), list(v), list(m), list(l), sf.sin, sf.cos))

        cls = symforce_function(f, name)
        times[f"symforce {name}"] = time.perf_counter() - start
        wrappers.append(wrapper(name, cls, [], ["q", "v", "m", "l"], n))
        start = time.perf_counter()
        inputs = [casadi.SX.sym(x, n) for x in "qvml"]
        qc, vc, mc, lc = ([x[i] for i in range(n)] for x in inputs)
        out = chain_map(n, qc, vc, mc, lc, casadi.sin, casadi.cos)
        casadi_function(f"ca_{name}", inputs, out)
        times[f"casadi {name}"] = time.perf_counter() - start
        names.append(name)

    write(os.path.join(OUT, "symforce.cc"), "\n".join(wrappers) + "\n")
    write(os.path.join(OUT, "casadi_names.txt"), "\n".join(names) + "\n")
    with open(os.path.join(OUT, "generation_times.txt"), "w") as fh:
        for k, t in times.items():
            fh.write(f"{k}\t{t:.3f} s\n")
            print(f"{k}: {t:.3f} s", file=sys.stderr)


if __name__ == "__main__":
    main()
