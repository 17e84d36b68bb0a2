#pragma once
// The Python module's conversions between Python values and the public API's types: numpy arrays
// for meshes and dense blocks, scipy.sparse (or CSR arrays) for sparse matrices, keyword
// arguments for options. Every check of a Python value raises a Python exception naming the
// argument (ValueError, TypeError), before the library sees the value.

#include "mcfbench/mcfbench.h"

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <string>

namespace mcfbench::python {

namespace py = pybind11;

/// V: an n x 3 array of real numbers (any float or integer dtype, converted to float64).
Vertices vertices_from(py::handle V, const std::string& what = "V");
/// F: an m x 3 array of integers (int32, int64 or another integer dtype), each within int32.
Faces faces_from(py::handle F, const std::string& what = "F");
/// B: an n x k (or length-n, read as n x 1) array of real numbers.
DenseMatrix dense_from(py::handle B, const std::string& what);

/// Copies, as float64 (n x 3, n x k) and int64 (m x 3) arrays the caller owns.
py::array_t<double> to_numpy(const Vertices& V);
py::array_t<double> to_numpy(const DenseMatrix& X);
py::array_t<double> to_numpy(const VerticesView& V);
py::array_t<long long> to_numpy(const Faces& F);

/// A symmetric sparse matrix as scipy.sparse.csc_matrix (a copy), or without scipy a dict of its
/// CSR arrays (data, indices, indptr, shape): the same arrays, since the matrix is symmetric.
py::object to_python(const SparseMatrix& A);
/// A square scipy.sparse matrix (any format) or dense 2-d array as the API's SparseMatrix.
SparseMatrix sparse_from(py::handle A, const std::string& what);

/// A keyword argument's value as an option value: bool, int (numpy's too), float, str. None is
/// "not given" (false is returned and `value` untouched); anything else raises TypeError.
bool value_from(py::handle object, const std::string& what, Value& value);

/// Options from keyword arguments (each a flag of `mcfbench flow` without its dashes), a config
/// (a dict with result.json's "config" keys, or the path of a JSON file) and max_memory; `name`
/// names them in error messages ("mcfbench.flow").
Options options_from(const py::dict& keywords, py::handle config, py::handle max_memory,
                     const std::string& name);

/// json.loads of a JSON text.
py::object from_json(const std::string& text);

}  // namespace mcfbench::python
