//! Plain option structs as Python classes: keyword construction, `repr`, field lists.

/// Apply the keyword arguments `kw` (an optional dict) to the fields of `s`, each extracted to
/// the field's type; an unknown name is a `TypeError`, a value of the wrong type too.
macro_rules! apply_kwargs {
    ($s:ident, $kw:expr, [$($f:ident),* $(,)?]) => {
        if let Some(kw) = $kw {
            for (k, v) in pyo3::types::PyDictMethods::iter(kw) {
                let k: String = k.extract()?;
                match k.as_str() {
                    $(stringify!($f) => {
                        $s.$f = v.extract().map_err(|e| {
                            pyo3::exceptions::PyTypeError::new_err(format!(
                                "{}: {}", stringify!($f), e
                            ))
                        })?
                    })*
                    _ => {
                        return Err(pyo3::exceptions::PyTypeError::new_err(format!(
                            "unexpected keyword argument `{k}` (fields: {})",
                            [$(stringify!($f)),*].join(", ")
                        )))
                    }
                }
            }
        }
    };
}

/// `Name(field=value, ...)` from the fields' Python reprs.
macro_rules! repr_fields {
    ($py:expr, $name:expr, $s:ident, [$($f:ident),* $(,)?]) => {{
        let mut parts: Vec<String> = Vec::new();
        $(
            let v = pyo3::IntoPyObjectExt::into_bound_py_any($s.$f.clone(), $py)?;
            parts.push(format!("{}={}", stringify!($f), v.repr()?));
        )*
        Ok(format!("{}({})", $name, parts.join(", ")))
    }};
}
