"""What bounds the Discrete Shells preview's time on the 130k bumpy plate?

    python -m benchmarks.preview_floor [--size 130k] [--k 100] [--repeats 3]

The preview's targets are 5 s and a tenth of the exact time for 100 shells modes at
130k vertices.  In one fresh process (the memory settings of the computation processes)
this measures, each as the fastest of ``--repeats`` runs:

- ``exact``: ``compute_spectrum(mesh, "shells", k)``, the baseline of the ratio target
  (one run);
- ``preview``: ``compute_spectrum(..., accuracy="preview")`` and its stages;
- ``assembly``: the shells Hessian and lumped mass (``operator_matrices``);
  the preview and the assembly get a fresh mesh for every run (a mesh caches its edges,
  hinges and normals, which would leave part of the work out);
- ``factorisation``: one factorisation of ``K - sigma M`` (``SPDSolver``, the shift of
  the exact solver with the rigid motions deflated), and one solve with it of a (3n, k)
  block.  Assembly, one factorisation and one block solve are the least work of any
  method that solves with the fine operator for k vectors (shift-invert Krylov methods,
  the hierarchical subspace iteration of Nasikun and Hildebrandt);
- ``projection``: ``P^T K P`` of the preview's reduced space three ways: the preview's
  six component blocks ``P_s^T K_ab P_s`` with scipy on two threads; Intel MKL's sparse
  BLAS ``mkl_sparse_sypr`` (the symmetric triple product) on ``kron(P_s, I3)``; MKL's
  ``mkl_sparse_spmm`` for the six blocks on MKL's own threads;
- ``product``: ``K X`` for an (3n, k) block, scipy on two threads
  (``core.products.threaded_product``) against MKL's ``mkl_sparse_d_mm``.

MKL is reached through the runtime library of the ``mkl`` wheel that ``core.factor``
loads for PARDISO; without it the MKL rows are left out.  Results go to
``benchmarks/results/preview_floor.json``.
"""

from __future__ import annotations

import argparse
import ctypes
import sys
import time
from pathlib import Path

import numpy as np
import scipy.sparse as sp

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from benchmarks.run import _in_child, make_mesh, save_result  # noqa: E402

_GENERAL = (20, 42, 50)  # matrix_descr: general, full, non-unit diagonal
_SYMMETRIC_UPPER = (21, 41, 50)  # symmetric, upper triangle stored
_NON_TRANSPOSE, _TRANSPOSE = 10, 11
_ROW_MAJOR = 101
_FULL_MULT = 90


class _Descr(ctypes.Structure):
    _fields_ = [("type", ctypes.c_int), ("mode", ctypes.c_int), ("diag", ctypes.c_int)]


class _MklCsr:
    """An MKL sparse handle on a CSR matrix (32-bit indices); keeps the arrays alive."""

    def __init__(self, lib, A: sp.csr_matrix):
        A = sp.csr_matrix(A)
        A.sort_indices()
        self.lib = lib
        self.shape = A.shape
        self.indptr = A.indptr.astype(np.int32)
        self.indices = A.indices.astype(np.int32)
        self.data = np.ascontiguousarray(A.data, dtype=np.float64)
        self.handle = ctypes.c_void_p()
        lib.mkl_sparse_d_create_csr.argtypes = [
            ctypes.POINTER(ctypes.c_void_p), ctypes.c_int, ctypes.c_int32, ctypes.c_int32,
            ctypes.c_void_p, ctypes.c_void_p, ctypes.c_void_p, ctypes.c_void_p,
        ]  # fmt: skip
        status = lib.mkl_sparse_d_create_csr(
            ctypes.byref(self.handle), 0, A.shape[0], A.shape[1], self.indptr.ctypes.data,
            self.indptr[1:].ctypes.data, self.indices.ctypes.data, self.data.ctypes.data,
        )  # fmt: skip
        if status != 0:
            raise RuntimeError(f"mkl_sparse_d_create_csr: status {status}")

    def __del__(self):
        self.lib.mkl_sparse_destroy(self.handle)


def _export(lib, handle: ctypes.c_void_p) -> sp.csr_matrix:
    """Copy an MKL CSR result into scipy and free it."""
    i32p = ctypes.POINTER(ctypes.c_int32)
    base, rows, cols = ctypes.c_int(), ctypes.c_int32(), ctypes.c_int32()
    start, end, idx = i32p(), i32p(), i32p()
    val = ctypes.POINTER(ctypes.c_double)()
    status = lib.mkl_sparse_d_export_csr(
        handle, ctypes.byref(base), ctypes.byref(rows), ctypes.byref(cols),
        ctypes.byref(start), ctypes.byref(end), ctypes.byref(idx), ctypes.byref(val),
    )  # fmt: skip
    if status != 0:
        raise RuntimeError(f"mkl_sparse_d_export_csr: status {status}")
    n = rows.value
    starts = np.ctypeslib.as_array(start, (n,)).astype(np.int64)
    ends = np.ctypeslib.as_array(end, (n,)).astype(np.int64)
    nnz = int(ends[-1] - base.value)
    out = sp.csr_matrix(
        (
            np.ctypeslib.as_array(val, (nnz,)).copy(),
            np.ctypeslib.as_array(idx, (nnz,)) - base.value,
            np.concatenate([starts, ends[-1:]]) - base.value,
        ),
        shape=(n, cols.value),
    )
    lib.mkl_sparse_destroy(handle)
    return out


def mkl_sypr(lib, P: sp.csr_matrix, K: sp.csr_matrix) -> sp.csr_matrix:
    """``P^T K P`` (upper triangle) by ``mkl_sparse_sypr``, K symmetric."""
    A, B = _MklCsr(lib, P), _MklCsr(lib, sp.triu(K, format="csr"))
    C = ctypes.c_void_p()
    lib.mkl_sparse_sypr.argtypes = [
        ctypes.c_int, ctypes.c_void_p, ctypes.c_void_p, _Descr,
        ctypes.POINTER(ctypes.c_void_p), ctypes.c_int,
    ]  # fmt: skip
    status = lib.mkl_sparse_sypr(
        _TRANSPOSE, A.handle, B.handle, _Descr(*_SYMMETRIC_UPPER), ctypes.byref(C), _FULL_MULT
    )
    if status != 0:
        raise RuntimeError(f"mkl_sparse_sypr: status {status}")
    return _export(lib, C)


def mkl_spmm(lib, op: int, A: sp.csr_matrix, B: sp.csr_matrix) -> sp.csr_matrix:
    """``op(A) B`` by ``mkl_sparse_spmm``."""
    a, b = _MklCsr(lib, A), _MklCsr(lib, B)
    C = ctypes.c_void_p()
    lib.mkl_sparse_spmm.argtypes = [
        ctypes.c_int,
        ctypes.c_void_p,
        ctypes.c_void_p,
        ctypes.POINTER(ctypes.c_void_p),
    ]
    status = lib.mkl_sparse_spmm(op, a.handle, b.handle, ctypes.byref(C))
    if status != 0:
        raise RuntimeError(f"mkl_sparse_spmm: status {status}")
    return _export(lib, C)


def mkl_mm(lib, K: _MklCsr, X: np.ndarray) -> np.ndarray:
    """``K X`` for dense X by ``mkl_sparse_d_mm`` (row-major)."""
    X = np.ascontiguousarray(X)
    Y = np.empty((K.shape[0], X.shape[1]))
    lib.mkl_sparse_d_mm.argtypes = [
        ctypes.c_int, ctypes.c_double, ctypes.c_void_p, _Descr, ctypes.c_int,
        ctypes.c_void_p, ctypes.c_int32, ctypes.c_int32, ctypes.c_double,
        ctypes.c_void_p, ctypes.c_int32,
    ]  # fmt: skip
    c = X.shape[1]
    status = lib.mkl_sparse_d_mm(
        _NON_TRANSPOSE, 1.0, K.handle, _Descr(*_GENERAL), _ROW_MAJOR,
        X.ctypes.data, c, c, 0.0, Y.ctypes.data, c,
    )  # fmt: skip
    if status != 0:
        raise RuntimeError(f"mkl_sparse_d_mm: status {status}")
    return Y


def _fastest(fn, repeats: int, fresh=None):
    """(seconds of the fastest run, result of the last); with ``fresh`` each run gets
    ``fresh()`` (made outside the clock) as its argument."""
    best, out = np.inf, None
    for _ in range(repeats):
        args = () if fresh is None else (fresh(),)
        t = time.perf_counter()
        out = fn(*args)
        best = min(best, time.perf_counter() - t)
    return best, out


def _measure(size: str, k: int, repeats: int) -> dict:
    import modalviewer as mv
    from modalviewer.core import preview as pv
    from modalviewer.core.eigen import DEFLATED_SHIFT_RTOL
    from modalviewer.core.factor import SPDSolver, _load_mkl
    from modalviewer.core.pipeline import operator_matrices
    from modalviewer.core.products import threaded_product
    from modalviewer.core.reduced_space import reduced_basis

    mesh = make_mesh(size)
    row: dict = {"size": size, "vertices": mesh.n_vertices, "k": k}
    t = time.perf_counter()
    exact = mv.compute_spectrum(mesh, "shells", k=k)
    row["exact_s"] = time.perf_counter() - t
    del exact

    def preview(fresh_mesh):
        return mv.compute_spectrum(fresh_mesh, "shells", k=k, accuracy="preview")

    def fresh():  # a mesh caches its edges, hinges and normals
        return make_mesh(size)

    row["preview_s"], spec = _fastest(preview, repeats, fresh)
    row["preview_stages_s"] = spec.parameters["preview"]["seconds_by_stage"]
    spec = None

    def assemble(fresh_mesh):
        return operator_matrices(fresh_mesh, "shells")

    row["assembly_s"], (K, mass) = _fastest(assemble, repeats, fresh)
    K = sp.csr_matrix(K)
    sigma = -DEFLATED_SHIFT_RTOL * float(np.median(K.diagonal() / mass))
    shifted = (K - sigma * sp.diags(mass)).tocsr()
    row["factorisation_s"], solver = _fastest(lambda: SPDSolver(shifted), repeats)
    row["factorisation_backend"] = solver.backend
    B = np.random.default_rng(1).standard_normal((K.shape[0], k))
    row["block_solve_s"], _ = _fastest(lambda: solver.solve(B), repeats)
    solver = shifted = B = None  # free the factor

    settings = pv.SPACE_SETTINGS["shells"]
    basis = reduced_basis(
        mesh, "shells", settings.samples(k), settings.radius_factor, settings.degree,
        candidates=mesh.n_vertices,
    )  # fmt: skip
    Ps = basis.scalar
    row["scalar_functions"] = int(Ps.shape[1])
    row["scalar_entries_per_row"] = Ps.nnz / Ps.shape[0]
    row["projection_scipy_blocks_s"], A0 = _fastest(lambda: pv._kron_projection(K, Ps), repeats)
    X = np.random.default_rng(0).standard_normal((K.shape[0], k))
    row["product_scipy_s"], Y0 = _fastest(lambda: threaded_product(K, X), repeats)

    lib = _load_mkl()
    row["mkl"] = lib is not None
    if lib is not None:
        Pv = sp.kron(Ps, sp.eye(3), format="csr")
        row["projection_mkl_sypr_s"], U = _fastest(lambda: mkl_sypr(lib, Pv, K), repeats)
        A1 = U + sp.triu(U, 1).T
        row["projection_mkl_sypr_rel_diff"] = float(abs(A1 - A0).max() / abs(A0).max())
        blocks = {(a, b): K[a::3][:, b::3].tocsr() for a in range(3) for b in range(a, 3)}

        def spmm_blocks():
            return [
                mkl_spmm(lib, _TRANSPOSE, Ps, mkl_spmm(lib, _NON_TRANSPOSE, Kab, Ps))
                for Kab in blocks.values()
            ]

        row["projection_mkl_spmm_blocks_s"], _ = _fastest(spmm_blocks, repeats)
        handle = _MklCsr(lib, K)
        row["product_mkl_s"], Y1 = _fastest(lambda: mkl_mm(lib, handle, X), repeats)
        row["product_mkl_rel_diff"] = float(abs(Y1 - Y0).max() / abs(Y0).max())
    return row


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--size", default="130k")
    parser.add_argument("--k", type=int, default=100)
    parser.add_argument("--repeats", type=int, default=3)
    args = parser.parse_args(argv)
    row = _in_child(_measure, args.size, args.k, args.repeats)
    row["target_s"] = min(5.0, row["exact_s"] / 10.0)
    row["fine_solve_floor_s"] = row["assembly_s"] + row["factorisation_s"] + row["block_solve_s"]
    save_result("preview_floor", row)
    print(f"{args.size} shells, k = {args.k}: exact {row['exact_s']:.1f} s, target "
          f"{row['target_s']:.2f} s (min of 5 s and a tenth)")  # fmt: skip
    print(f"preview {row['preview_s']:.2f} s: {row['preview_stages_s']}")
    print(f"assembly {row['assembly_s']:.2f} s + one factorisation "
          f"{row['factorisation_s']:.2f} s ({row['factorisation_backend']}) + one solve of "
          f"{args.k} right-hand sides {row['block_solve_s']:.2f} s = "
          f"{row['fine_solve_floor_s']:.2f} s")  # fmt: skip
    print(f"P^T K P: scipy blocks on two threads {row['projection_scipy_blocks_s']:.2f} s", end="")
    if row["mkl"]:
        print(f", MKL sypr {row['projection_mkl_sypr_s']:.2f} s, MKL spmm blocks "
              f"{row['projection_mkl_spmm_blocks_s']:.2f} s")  # fmt: skip
        print(f"K X: scipy on two threads {row['product_scipy_s']:.3f} s, MKL "
              f"{row['product_mkl_s']:.3f} s")  # fmt: skip
    else:
        print(f"\nK X: scipy on two threads {row['product_scipy_s']:.3f} s (no MKL here)")


if __name__ == "__main__":
    main()
