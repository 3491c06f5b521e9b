"""Readers of frictional-contact problems written by other codes (FCLIB HDF5, Siconos text).

- FCLIB local problems (HDF5 group ``/fclib_local``): W, q, mu as stored.
- FCLIB global problems (``/fclib_global``): M v = H r + f, u = H^T v + w, condensed to a local
  problem W = H^T M^-1 H, q = H^T M^-1 f + w (sparse LU of M).
- Siconos text files (``frictionContact_printInFile``): dimension, number of contacts, the
  matrix (dense, or Siconos's sparse-block storage), q, mu.

Matrices in FCLIB files are CSparse-style groups {m, n, nz, nzmax, p, i, x}: nz = -2 is CSR,
nz = -1 CSC, nz >= 0 triplets (i rows, p columns). The ``/solution`` and ``/guesses`` groups are
ignored on purpose: in these files they are not solutions.
"""

from __future__ import annotations

from dataclasses import dataclass
from importlib import resources
from pathlib import Path

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from clearbench.ref_solver.contact_problem import ContactProblem


class UnsupportedProblemError(ValueError):
    """The file holds a problem our solver does not model (e.g. rolling friction)."""


@dataclass(frozen=True, eq=False)
class LoadedProblem:
    """A problem read from a file.

    Attributes
    ----------
    name : str
        File name without directory.
    kind : str
        "local", "global" (condensed) or "siconos-text".
    problem : ContactProblem
    title, description : str
        Metadata stored in the file (FCLIB ``info`` group), empty if none.
    """

    name: str
    kind: str
    problem: ContactProblem
    title: str = ""
    description: str = ""


def _read_matrix(group) -> sp.csr_matrix:
    """CSparse-style FCLIB matrix group -> CSR (float64)."""
    n_rows = int(np.asarray(group["m"]).ravel()[0])
    n_cols = int(np.asarray(group["n"]).ravel()[0])
    nz = int(np.asarray(group["nz"]).ravel()[0])
    p = np.asarray(group["p"], dtype=np.int64).ravel()
    i = np.asarray(group["i"], dtype=np.int64).ravel()
    x = np.asarray(group["x"], dtype=np.float64).ravel()
    shape = (n_rows, n_cols)
    if nz == -2:
        nnz = int(p[-1])
        return sp.csr_matrix((x[:nnz], i[:nnz], p), shape=shape)
    if nz == -1:
        nnz = int(p[-1])
        return sp.csc_matrix((x[:nnz], i[:nnz], p), shape=shape).tocsr()
    if nz >= 0:
        return sp.coo_matrix((x[:nz], (i[:nz], p[:nz])), shape=shape).tocsr()
    raise ValueError(f"unknown FCLIB matrix storage nz = {nz}")


def _text(group, key: str) -> str:
    if key not in group:
        return ""
    value = group[key][()]
    if isinstance(value, bytes):
        return value.decode("utf-8", errors="replace").strip()
    return str(value).strip()


def condense_global(M, H, f: np.ndarray, w: np.ndarray) -> tuple[sp.csr_matrix, np.ndarray]:
    """W = H^T M^-1 H and q = H^T M^-1 f + w for a global problem.

    M (n, n) sparse invertible, H (n, m) sparse, f (n,), w (m,). Returns W as CSR (m, m).
    """
    M = sp.csc_matrix(M)
    H = sp.csc_matrix(H)
    lu = spla.splu(M)
    Minv_H = lu.solve(H.toarray()) if H.shape[1] else np.zeros(H.shape)
    W = sp.csr_matrix(H.T @ Minv_H)
    W.eliminate_zeros()
    q = H.T @ lu.solve(np.asarray(f, dtype=np.float64)) + np.asarray(w, dtype=np.float64)
    return W, np.asarray(q).ravel()


def read_fclib(path: str | Path) -> LoadedProblem:
    """Read an FCLIB HDF5 file (local or global problem)."""
    import h5py  # lazy: h5py is loaded only to read FCLIB's HDF5 files

    path = Path(path)
    with h5py.File(path, "r") as handle:
        if "fclib_local" in handle:
            group = handle["fclib_local"]
            _check_spacedim(group, path)
            W = _read_matrix(group["W"])
            q = np.asarray(group["vectors/q"], dtype=np.float64)
            mu = np.asarray(group["vectors/mu"], dtype=np.float64)
            kind = "local"
        elif "fclib_global" in handle:
            group = handle["fclib_global"]
            _check_spacedim(group, path)
            M = _read_matrix(group["M"])
            H = _read_matrix(group["H"])
            f = np.asarray(group["vectors/f"], dtype=np.float64)
            w = np.asarray(group["vectors/w"], dtype=np.float64)
            mu = np.asarray(group["vectors/mu"], dtype=np.float64)
            W, q = condense_global(M, H, f, w)
            kind = "global"
        elif "fclib_global_rolling" in handle:
            raise UnsupportedProblemError(
                f"{path.name}: global problem with rolling friction (5 rows per contact); "
                "the solver models sliding friction only"
            )
        else:
            raise ValueError(f"{path.name}: no fclib_local or fclib_global group")
        info = group["info"] if "info" in group else {}
        title = _text(info, "title") if info else ""
        description = _text(info, "description") if info else ""
    return LoadedProblem(path.name, kind, ContactProblem(W, q, mu), title, description)


def _check_spacedim(group, path: Path) -> None:
    if "spacedim" in group:
        dim = int(np.asarray(group["spacedim"]).ravel()[0])
        if dim != 3:
            raise UnsupportedProblemError(f"{path.name}: space dimension {dim}, only 3 supported")


def read_siconos_text(path: str | Path) -> LoadedProblem:
    """Read a Siconos ``frictionContact_printInFile`` text file (3D problems).

    Layout (whitespace separated): dimension d, number of contacts nc, then the matrix as
    ``NM_write_in_file`` writes it: storage type (0 dense, column-major values; 1 sparse block),
    size0, size1, then for sparse block (``SBM_write_in_file``): nbblocks, blocknumber0,
    blocknumber1, cumulative block sizes (rows, then columns), filled1, filled2, index1_data
    (block-row pointers), index2_data (block-column indices), and per block its number followed
    by its values column-major. Then q (d nc values) and mu (nc values).
    """
    path = Path(path)
    tokens = path.read_text().split()
    pos = 0

    def take(count: int, kind=float) -> np.ndarray:
        nonlocal pos
        if pos + count > len(tokens):
            raise ValueError(f"{path.name}: file ends early (wanted {count} more values)")
        chunk = tokens[pos:pos + count]
        pos += count
        return np.array([kind(t) for t in chunk]) if kind is float else np.array(
            [int(t) for t in chunk], dtype=np.int64)

    dim, nc = (int(v) for v in take(2, int))
    if dim != 3:
        raise UnsupportedProblemError(f"{path.name}: dimension {dim}, only 3 supported")
    storage, size0, size1 = (int(v) for v in take(3, int))
    m = dim * nc
    if (size0, size1) != (m, m):
        raise ValueError(f"{path.name}: matrix {size0}x{size1} but {nc} contacts")
    if storage == 0:
        W = sp.csr_matrix(take(m * m).reshape((m, m), order="F"))
    elif storage == 1:
        W = _read_sparse_block(take, path)
    else:
        raise ValueError(f"{path.name}: unsupported matrix storage type {storage}")
    q = take(m)
    mu = take(nc)
    return LoadedProblem(path.name, "siconos-text", ContactProblem(W, q, mu))


def _read_sparse_block(take, path: Path) -> sp.csr_matrix:
    nbblocks, blocknumber0, blocknumber1 = (int(v) for v in take(3, int))
    rowsizes = take(blocknumber0, int)
    colsizes = take(blocknumber1, int)
    filled1, filled2 = (int(v) for v in take(2, int))
    index1 = take(filled1, int)
    index2 = take(filled2, int)
    row_start = np.concatenate([[0], rowsizes])
    col_start = np.concatenate([[0], colsizes])
    rows, cols, vals = [], [], []
    for block_row in range(filled1 - 1):
        n_rows = row_start[block_row + 1] - row_start[block_row]
        for block_num in range(index1[block_row], index1[block_row + 1]):
            block_col = index2[block_num]
            n_cols = col_start[block_col + 1] - col_start[block_col]
            number = int(take(1, int)[0])
            if number != block_num:
                raise ValueError(f"{path.name}: block numbering broken ({number} != {block_num})")
            values = take(n_rows * n_cols).reshape((n_rows, n_cols), order="F")
            rr, cc = np.meshgrid(np.arange(n_rows), np.arange(n_cols), indexing="ij")
            rows.append((rr + row_start[block_row]).ravel())
            cols.append((cc + col_start[block_col]).ravel())
            vals.append(values.ravel())
    if nbblocks != sum(v.size > 0 for v in vals):
        raise ValueError(f"{path.name}: {nbblocks} blocks announced, {len(vals)} read")
    shape = (int(rowsizes[-1]), int(colsizes[-1]))
    return sp.coo_matrix(
        (np.concatenate(vals), (np.concatenate(rows), np.concatenate(cols))), shape=shape
    ).tocsr()


def load_problem(path: str | Path) -> LoadedProblem:
    """Read any supported file: ``.hdf5``/``.h5`` (FCLIB) or ``.dat`` (Siconos text)."""
    path = Path(path)
    if not path.is_file():
        raise FileNotFoundError(f"no such problem file: {path}")
    if path.suffix == ".dat":
        return read_siconos_text(path)
    return read_fclib(path)


def shipped_problem_dir() -> Path:
    """Folder of the FCLIB problems shipped with clearbench (harness/fclib/data)."""
    return Path(str(resources.files("clearbench.harness.fclib") / "data"))


def shipped_problem_files() -> list[Path]:
    """The shipped problem files, sorted by name."""
    folder = shipped_problem_dir()
    return sorted(p for p in folder.iterdir() if p.suffix in (".hdf5", ".dat"))
