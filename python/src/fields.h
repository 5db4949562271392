#pragma once
// The option, report and result classes described once, as a table of their fields: each field
// is bound as an attribute with its doc string, and the same table gives the class its pickling
// (a tuple of the fields' values, in order), __eq__ (every field equal, arrays element by
// element, so a pickle round trip compares equal bit for bit) and, where the class has no summary
// of its own, a readable __repr__ ("OverallOptions(constraint_tolerance=1e-12, ...)"). Option
// classes also get a keyword constructor (`FigureOptions(width=320)`) and accept a dict of their
// fields wherever a function takes them.
//
//   py::class_<AccuracyReport> c(m, "AccuracyReport", doc);
//   Fields<AccuracyReport>(c, "AccuracyReport")
//       .Member("enabled", &AccuracyReport::enabled, "tolerance > 0 was asked for")
//       ...
//       .Finish();
#include <pybind11/eigen.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <Eigen/Core>
#include <functional>
#include <memory>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

#include "convert.h"

namespace flexkin::python {

// "<(20, 21, 2) array>", or the values of a short 1-D array ("[1, 2.5]"), or "None".
std::string ArrayText(py::handle array);

// A field's value as text in a repr.
template <typename M>
std::string FieldText(const M& value) {
  if constexpr (std::is_same_v<M, bool>) {
    return value ? "True" : "False";
  } else if constexpr (std::is_integral_v<M>) {
    return std::to_string(value);
  } else if constexpr (std::is_floating_point_v<M>) {
    return Num(value);
  } else if constexpr (std::is_same_v<M, std::string>) {
    return Quoted(value);
  } else if constexpr (std::is_base_of_v<py::handle, M>) {
    return ArrayText(value);
  } else if constexpr (std::is_base_of_v<Eigen::EigenBase<M>, M>) {
    return ArrayText(py::cast(value));
  } else {
    return py::repr(py::cast(value));
  }
}

// A field's value as a Python object (a copy of a C++ value).
template <typename M>
py::object ToObject(const M& value) {
  if constexpr (std::is_base_of_v<py::handle, M>) {
    return py::reinterpret_borrow<py::object>(value);
  } else {
    return py::cast(value);
  }
}

// An Eigen matrix or vector as a C-ordered numpy copy; None where it is empty if `optional`.
template <typename E>
py::object EigenOut(const E& value, bool optional) {
  if (optional && value.size() == 0) return py::none();
  if constexpr (E::ColsAtCompileTime == 1) {
    return ToArray(Eigen::VectorXd(value));
  } else {
    return ToArray(Points(value));
  }
}
// The inverse: None is empty.
template <typename E>
E EigenIn(py::handle value) {
  return value.is_none() ? E() : py::cast<E>(value);
}

// Whether two values of a field are the same: numbers bit for bit (NaN is never the same), arrays
// of the same shape element by element, other classes by their __eq__.
bool SameObjects(py::handle a, py::handle b);
template <typename M>
bool Same(const M& a, const M& b) {
  if constexpr (std::is_arithmetic_v<M> || std::is_enum_v<M> || std::is_same_v<M, std::string>) {
    return a == b;
  } else if constexpr (std::is_base_of_v<py::handle, M>) {
    return SameObjects(a, b);
  } else if constexpr (std::is_base_of_v<Eigen::EigenBase<M>, M>) {
    return a.rows() == b.rows() && a.cols() == b.cols() && (a.array() == b.array()).all();
  } else {
    return py::cast(a).equal(py::cast(b));
  }
}

template <typename T>
class Fields {
 public:
  struct Field {
    std::string name;
    std::function<py::object(const T&)> get;
    std::function<void(T&, py::handle)> set;
    std::function<bool(const T&, const T&)> same;
    std::function<std::string(const T&)> text;
  };
  struct Table {
    std::string type;
    std::vector<Field> fields;
  };

  Fields(py::class_<T>& cls, const char* type) : cls_(cls), table_(std::make_shared<Table>()) {
    table_->type = type;
    Registered() = table_;
  }

  // The table of T's class (bound once per process).
  static const Table& Of() { return *Registered(); }

  // A data member bound as it is, read-only unless `writable`.
  template <typename M>
  Fields& Member(const char* name, M T::*member, const char* doc, bool writable = false) {
    if (writable) {
      cls_.def_readwrite(name, member, doc);
    } else {
      cls_.def_readonly(name, member, doc);
    }
    return Add(
        name, [member](const T& t) -> const M& { return t.*member; },
        [member](T& t, py::handle value) { t.*member = py::cast<M>(value); });
  }

  // A field read by get(const T&) and written by set(T&, py::handle) (converting and checking):
  // an attribute, read-only unless `writable`; the setter also restores a pickled value.
  template <typename Get, typename Set>
  Fields& Property(const char* name, Get get, Set set, const char* doc, bool writable = false) {
    if (writable) {
      cls_.def_property(name, get, set, doc);
    } else {
      cls_.def_property_readonly(name, get, doc);
    }
    return Add(name, get, set);
  }

  // An Eigen member (vector or matrix) as a read-only attribute that gives a numpy copy; None
  // where it is empty if `optional` (and None restores it empty).
  template <typename E>
  Fields& Array(const char* name, E T::*member, const char* doc, bool optional = false) {
    return Property(
        name, [member, optional](const T& t) { return EigenOut(t.*member, optional); },
        [member](T& t, py::handle value) { t.*member = EigenIn<E>(value); }, doc);
  }

  // A member of a member (result.run.seconds) as a read-only attribute (a copy).
  template <typename S, typename M>
  Fields& Nested(const char* name, S T::*outer, M S::*inner, const char* doc) {
    return Property(
        name, [outer, inner](const T& t) -> M { return (t.*outer).*inner; },
        [outer, inner](T& t, py::handle value) { (t.*outer).*inner = py::cast<M>(value); }, doc);
  }

  // A field that is pickled and compared but is no attribute (a solver's memory).
  template <typename Get, typename Set>
  Fields& Hidden(const char* name, Get get, Set set) {
    return Add(name, get, set);
  }

  // A keyword constructor: T() with the fields named by the keywords set (InputError naming an
  // unknown keyword, listing the fields).
  Fields& KeywordInit() {
    auto table = table_;
    cls_.def(py::init([table](const py::kwargs& values) {
      T t;
      Apply(*table, values, "", &t);
      return t;
    }));
    return *this;
  }

  // validate(): raises InputError for the first problem of T::Validate(), naming the member
  // (`example` is one such name, for the doc string).
  Fields& Validate(const char* example) {
    cls_.def(
        "validate", [](const T& t) { ThrowIfAny(t.Validate()); },
        (std::string("Raises InputError for the first problem, naming the member ('") + example +
         "'); returns None if there is none.")
            .c_str());
    return *this;
  }

  // Defines __eq__ and pickling, and `Type(field=value, ...)` as __repr__ if `repr`. `check`
  // runs on an unpickled object (to validate it or derive what is not pickled).
  void Finish(bool repr = true, std::function<void(T&)> check = nullptr) {
    auto table = table_;
    if (repr) {
      cls_.def(
          "__repr__",
          [table](const T& t) {
            std::string text = table->type + "(";
            for (size_t i = 0; i < table->fields.size(); ++i) {
              const Field& f = table->fields[i];
              text += (i > 0 ? ", " : "") + f.name + "=" + f.text(t);
            }
            return text + ")";
          },
          ("The fields as text: " + table->type + "(name=value, ...).").c_str());
    }
    cls_.def(
        "__eq__",
        [table](const T& a, const T& b) {
          for (const Field& f : table->fields) {
            if (!f.same(a, b)) return false;
          }
          return true;
        },
        py::is_operator(), "Every field equal (arrays element by element).");
    cls_.def(py::pickle(
        [table](const T& t) {
          py::tuple state(table->fields.size());
          for (size_t i = 0; i < table->fields.size(); ++i) state[i] = table->fields[i].get(t);
          return state;
        },
        [table, check](const py::tuple& state) {
          StateTuple(state, table->fields.size(), table->type.c_str());
          T t;
          for (size_t i = 0; i < table->fields.size(); ++i) table->fields[i].set(t, state[i]);
          if (check) check(t);
          return t;
        }));
  }

  // Sets the fields named by the keys of `values` (a dict); InputError naming `prefix` + the key
  // for an unknown one.
  static void Apply(const Table& table, py::handle values, const std::string& prefix, T* t) {
    for (const auto& [key, value] : py::reinterpret_borrow<py::dict>(values)) {
      const std::string name = py::str(key);
      const Field* field = nullptr;
      std::string names;
      for (const Field& f : table.fields) {
        if (f.name == name) field = &f;
        names += (names.empty() ? "" : ", ") + f.name;
      }
      if (field == nullptr) {
        ThrowInput(prefix + name, "is not a field of " + table.type + "; expected one of " + names,
                   Quoted(name), names);
      }
      try {
        field->set(*t, value);
      } catch (const InputError& e) {
        Problem p = e.problem();
        p.field = prefix + p.field;
        throw InputError(p);
      } catch (const py::cast_error&) {
        const std::string type = py::str(py::type::of(value).attr("__name__"));
        ThrowInput(prefix + name, "has a value of type " + type + " that does not fit the field",
                   type);
      }
    }
  }

 private:
  template <typename Get, typename Set>
  Fields& Add(const char* name, Get get, Set set) {
    Field f;
    f.name = name;
    f.get = [get](const T& t) { return ToObject(get(t)); };
    f.set = set;
    f.same = [get](const T& a, const T& b) { return Same(get(a), get(b)); };
    f.text = [get](const T& t) { return FieldText(get(t)); };
    table_->fields.push_back(std::move(f));
    return *this;
  }

  static std::shared_ptr<const Table>& Registered() {
    static std::shared_ptr<const Table> table;
    return table;
  }

  py::class_<T>& cls_;
  std::shared_ptr<Table> table_;
};

// An options argument: an instance of T, a dict of its fields (set on T's defaults) or None (the
// defaults); InputError naming `name` otherwise.
template <typename T>
T OptionsArg(py::handle object, const std::string& name) {
  const typename Fields<T>::Table& table = Fields<T>::Of();
  if (object.is_none()) return T();
  if (py::isinstance<T>(object)) return py::cast<T>(object);
  if (py::isinstance<py::dict>(object)) {
    T t;
    Fields<T>::Apply(table, object, name + ".", &t);
    return t;
  }
  const std::string type = py::str(py::type::of(object).attr("__name__"));
  ThrowInput(name, "is a " + type + "; expected None, " + table.type + " or a dict of its fields",
             type);
}

}  // namespace flexkin::python
