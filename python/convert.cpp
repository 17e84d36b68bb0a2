#include "convert.h"

#include <climits>
#include <cstdint>

namespace mcfbench::python {

using namespace pybind11::literals;

namespace {

std::string shape_text(const py::array& a) {
  std::string s = "(";
  for (py::ssize_t d = 0; d < a.ndim(); ++d) s += (d ? ", " : "") + std::to_string(a.shape(d));
  return s + (a.ndim() == 1 ? ",)" : ")");
}

std::string type_name(py::handle object) {
  return py::str(py::type::handle_of(object).attr("__name__"));
}

/// `object` as a numpy array (array-likes, lists of lists too); TypeError naming `what`
/// otherwise.
py::array array_from(py::handle object, const std::string& what, const char* expected) {
  if (object.is_none()) throw py::type_error(what + ": expected " + expected + ", got None");
  py::array a;
  try {
    a = py::module_::import("numpy").attr("asarray")(object);
  } catch (const py::error_already_set&) {
    throw py::type_error(what + ": expected " + expected + ", got " + type_name(object));
  }
  return a;
}

char kind_of(const py::array& a) {
  return a.dtype().kind();
}

}  // namespace

Vertices vertices_from(py::handle V, const std::string& what) {
  const py::array a = array_from(V, what, "an n x 3 array of vertex positions");
  if (kind_of(a) != 'f' && kind_of(a) != 'i' && kind_of(a) != 'u')
    throw py::type_error(what + ": expected real coordinates, got dtype " +
                         std::string(py::str(a.dtype())));
  if (a.ndim() != 2 || a.shape(1) != 3)
    throw py::value_error(what + ": expected an n x 3 array of vertex positions, got shape " +
                          shape_text(a));
  const auto d = py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(a);
  Vertices out(d.shape(0), 3);
  const auto r = d.unchecked<2>();
  for (py::ssize_t i = 0; i < d.shape(0); ++i)
    for (int c = 0; c < 3; ++c) out(i, c) = r(i, c);
  return out;
}

Faces faces_from(py::handle F, const std::string& what) {
  const py::array a = array_from(F, what, "an m x 3 array of vertex indices");
  if (kind_of(a) != 'i' && kind_of(a) != 'u')
    throw py::type_error(what + ": expected integer vertex indices (int32 or int64), got dtype " +
                         std::string(py::str(a.dtype())));
  if (a.ndim() != 2 || a.shape(1) != 3)
    throw py::value_error(what + ": expected an m x 3 array of vertex indices, got shape " +
                          shape_text(a));
  Faces out(a.shape(0), 3);
  const auto check = [&](auto value, py::ssize_t f) {
    if (value > INT_MAX || value < INT_MIN)
      throw py::value_error(what + ": face " + std::to_string(f) + " references vertex " +
                            std::to_string(value) + ", beyond the int32 range of indices");
    return static_cast<int>(value);
  };
  if (kind_of(a) == 'u') {
    const auto d = py::array_t<std::uint64_t, py::array::c_style | py::array::forcecast>::ensure(a);
    const auto r = d.unchecked<2>();
    for (py::ssize_t f = 0; f < d.shape(0); ++f)
      for (int c = 0; c < 3; ++c)
        out(f, c) = check(static_cast<long long>(std::min<std::uint64_t>(r(f, c), LLONG_MAX)), f);
  } else {
    const auto d = py::array_t<long long, py::array::c_style | py::array::forcecast>::ensure(a);
    const auto r = d.unchecked<2>();
    for (py::ssize_t f = 0; f < d.shape(0); ++f)
      for (int c = 0; c < 3; ++c) out(f, c) = check(r(f, c), f);
  }
  return out;
}

DenseMatrix dense_from(py::handle B, const std::string& what) {
  const py::array a = array_from(B, what, "an array of real numbers");
  if (kind_of(a) != 'f' && kind_of(a) != 'i' && kind_of(a) != 'u')
    throw py::type_error(what + ": expected real numbers, got dtype " +
                         std::string(py::str(a.dtype())));
  if (a.ndim() != 1 && a.ndim() != 2)
    throw py::value_error(what + ": expected an n x k array, got shape " + shape_text(a));
  const auto d = py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(a);
  const py::ssize_t rows = d.shape(0), cols = d.ndim() == 2 ? d.shape(1) : 1;
  DenseMatrix out(rows, cols);
  const double* p = d.data();
  for (py::ssize_t i = 0; i < rows; ++i)
    for (py::ssize_t j = 0; j < cols; ++j) out(i, j) = p[i * cols + j];
  return out;
}

template <class Matrix>
py::array_t<double> dense_to_numpy(const Matrix& X) {
  py::array_t<double> a({py::ssize_t(X.rows()), py::ssize_t(X.cols())});
  auto w = a.template mutable_unchecked<2>();
  for (Eigen::Index i = 0; i < X.rows(); ++i)
    for (Eigen::Index j = 0; j < X.cols(); ++j) w(i, j) = X(i, j);
  return a;
}

py::array_t<double> to_numpy(const Vertices& V) {
  return dense_to_numpy(V);
}
py::array_t<double> to_numpy(const DenseMatrix& X) {
  return dense_to_numpy(X);
}
py::array_t<double> to_numpy(const VerticesView& V) {
  return dense_to_numpy(V);
}

py::array_t<long long> to_numpy(const Faces& F) {
  py::array_t<long long> a({py::ssize_t(F.rows()), py::ssize_t(3)});
  auto w = a.mutable_unchecked<2>();
  for (Eigen::Index i = 0; i < F.rows(); ++i)
    for (int j = 0; j < 3; ++j) w(i, j) = F(i, j);
  return a;
}

py::object to_python(const SparseMatrix& A) {
  const auto nnz = py::ssize_t(A.nonZeros());
  py::array_t<double> data(nnz);
  py::array_t<int> indices(nnz), indptr(py::ssize_t(A.outerSize() + 1));
  std::copy(A.valuePtr(), A.valuePtr() + nnz, data.mutable_data());
  std::copy(A.innerIndexPtr(), A.innerIndexPtr() + nnz, indices.mutable_data());
  std::copy(A.outerIndexPtr(), A.outerIndexPtr() + A.outerSize() + 1, indptr.mutable_data());
  const py::tuple shape = py::make_tuple(A.rows(), A.cols());
  try {
    const py::module_ sparse = py::module_::import("scipy.sparse");
    return sparse.attr("csc_matrix")(py::make_tuple(data, indices, indptr), "shape"_a = shape);
  } catch (const py::error_already_set& e) {
    if (!e.matches(PyExc_ImportError)) throw;
  }
  py::dict d;
  d["data"] = data;
  d["indices"] = indices;
  d["indptr"] = indptr;
  d["shape"] = shape;
  d["format"] = "csr";
  return d;
}

SparseMatrix sparse_from(py::handle A, const std::string& what) {
  py::object csc;
  if (py::hasattr(A, "tocsc")) {
    csc = A.attr("tocsc")();
  } else {
    const DenseMatrix dense = dense_from(A, what);
    if (dense.rows() != dense.cols())
      throw py::value_error(what + ": expected a square matrix, got " +
                            std::to_string(dense.rows()) + " x " + std::to_string(dense.cols()));
    return dense.sparseView();
  }
  const py::tuple shape = csc.attr("shape");
  const auto rows = shape[0].cast<Eigen::Index>(), cols = shape[1].cast<Eigen::Index>();
  if (rows != cols)
    throw py::value_error(what + ": expected a square matrix, got " + std::to_string(rows) + " x " +
                          std::to_string(cols));
  csc.attr("sum_duplicates")();
  const auto data =
      py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(csc.attr("data"));
  const auto indices =
      py::array_t<int, py::array::c_style | py::array::forcecast>::ensure(csc.attr("indices"));
  const auto indptr =
      py::array_t<int, py::array::c_style | py::array::forcecast>::ensure(csc.attr("indptr"));
  SparseMatrix out = Eigen::Map<const SparseMatrix>(rows, cols, data.size(), indptr.data(),
                                                    indices.data(), data.data());
  out.makeCompressed();
  return out;
}

bool value_from(py::handle object, const std::string& what, Value& value) {
  if (object.is_none()) return false;
  const py::module_ numpy = py::module_::import("numpy");
  if (PyBool_Check(object.ptr()) || py::isinstance(object, numpy.attr("bool_"))) {
    value = Value(object.cast<bool>());
  } else if (PyFloat_Check(object.ptr()) || py::isinstance(object, numpy.attr("floating"))) {
    value = Value(py::cast<double>(py::float_(py::reinterpret_borrow<py::object>(object))));
  } else if (PyIndex_Check(object.ptr())) {
    const py::int_ i = py::reinterpret_steal<py::int_>(PyNumber_Index(object.ptr()));
    if (!i) throw py::error_already_set();
    int overflow = 0;
    const long long v = PyLong_AsLongLongAndOverflow(i.ptr(), &overflow);
    if (overflow)
      throw py::value_error(what + ": " + std::string(py::str(object)) + " is out of range");
    value = Value(v);
  } else if (py::isinstance<py::str>(object)) {
    value = Value(object.cast<std::string>());
  } else {
    throw py::type_error(what + ": expected a number, a string or True/False, got " +
                         type_name(object));
  }
  return true;
}

Options options_from(const py::dict& keywords, py::handle config, py::handle max_memory,
                     const std::string& name) {
  Options o;
  o.name = name;
  for (const auto& [key, object] : keywords) {
    const std::string k = py::str(key);
    Value v(false);
    if (value_from(object, name + ": " + k, v)) o.settings.emplace_back(k, std::move(v));
  }
  if (!config.is_none()) {
    if (py::isinstance<py::dict>(config))
      o.config_json = py::module_::import("json").attr("dumps")(config).cast<std::string>();
    else if (py::isinstance<py::str>(config) ||
             py::isinstance(config, py::module_::import("os").attr("PathLike")))
      o.config_file = py::str(py::module_::import("os").attr("fspath")(config));
    else
      throw py::type_error(name + ": config: expected a dict or the path of a JSON file, got " +
                           type_name(config));
  }
  if (!max_memory.is_none()) {
    if (py::isinstance<py::str>(max_memory))
      o.max_memory = max_memory.cast<std::string>();
    else if (PyIndex_Check(max_memory.ptr()) && !PyBool_Check(max_memory.ptr()))
      o.max_memory = std::string(py::str(max_memory));
    else
      throw py::type_error(name +
                           ": max_memory: expected a size (\"8G\", bytes) or \"none\", got " +
                           type_name(max_memory));
  }
  return o;
}

py::object from_json(const std::string& text) {
  return py::module_::import("json").attr("loads")(text);
}

}  // namespace mcfbench::python
