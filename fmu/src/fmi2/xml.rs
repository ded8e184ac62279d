//! Generation of `modelDescription.xml` from a [`Model`]'s variable table, units and
//! enumerations, with the same GUID the binary checks in `fmi2Instantiate`.

use super::instance::{guid, Model};
use super::logger::Category;
use super::variables::{Causality, Kind, Variability};
use std::fmt::Write;

/// Escape text for an XML attribute value.
pub fn escape_xml(s: &str) -> String {
    let mut out = String::with_capacity(s.len());
    for ch in s.chars() {
        match ch {
            '&' => out.push_str("&amp;"),
            '<' => out.push_str("&lt;"),
            '>' => out.push_str("&gt;"),
            '"' => out.push_str("&quot;"),
            '\'' => out.push_str("&apos;"),
            '\n' => out.push_str("&#10;"),
            c => out.push(c),
        }
    }
    out
}

/// A real number as the shortest decimal that reads back to the same `f64`.
fn real(v: f64) -> String {
    format!("{v:?}")
}

/// The complete `modelDescription.xml` of model `M`.
pub fn model_description<M: Model>(generation_tool: &str) -> String {
    let mut x = String::new();
    let e = escape_xml;
    let id = M::MODEL_IDENTIFIER;
    let _ = writeln!(x, r#"<?xml version="1.0" encoding="UTF-8"?>"#);
    let _ = writeln!(
        x,
        r#"<fmiModelDescription fmiVersion="2.0" modelName="{}" guid="{}" description="{}" generationTool="{}" variableNamingConvention="flat" numberOfEventIndicators="0">"#,
        e(id),
        guid::<M>(),
        e(M::DESCRIPTION),
        e(generation_tool)
    );
    let _ = writeln!(
        x,
        r#"  <CoSimulation modelIdentifier="{}" needsExecutionTool="false" canHandleVariableCommunicationStepSize="true" canInterpolateInputs="false" maxOutputDerivativeOrder="0" canRunAsynchronuously="false" canBeInstantiatedOnlyOncePerProcess="false" canNotUseMemoryManagementFunctions="true" canGetAndSetFMUstate="true" canSerializeFMUstate="true" providesDirectionalDerivative="false"/>"#,
        e(id)
    );
    let _ = writeln!(x, "  <UnitDefinitions>");
    for u in M::UNITS {
        let mut attrs = String::new();
        for (name, exp) in [("kg", u.kg), ("m", u.m), ("s", u.s)] {
            if exp != 0 {
                let _ = write!(attrs, r#" {name}="{exp}""#);
            }
        }
        let _ = writeln!(
            x,
            r#"    <Unit name="{}"><BaseUnit{attrs}/></Unit>"#,
            e(u.name)
        );
    }
    let _ = writeln!(x, "  </UnitDefinitions>");
    if !M::ENUMERATIONS.is_empty() {
        let _ = writeln!(x, "  <TypeDefinitions>");
        for t in M::ENUMERATIONS {
            let _ = writeln!(
                x,
                r#"    <SimpleType name="{}" description="{}">"#,
                e(t.name),
                e(t.description)
            );
            let _ = writeln!(x, "      <Enumeration>");
            for i in t.items {
                let _ = writeln!(
                    x,
                    r#"        <Item name="{}" value="{}" description="{}"/>"#,
                    e(i.name),
                    i.value,
                    e(i.description)
                );
            }
            let _ = writeln!(x, "      </Enumeration>");
            let _ = writeln!(x, "    </SimpleType>");
        }
        let _ = writeln!(x, "  </TypeDefinitions>");
    }
    let _ = writeln!(x, "  <LogCategories>");
    for c in Category::ALL {
        let _ = writeln!(
            x,
            r#"    <Category name="{}" description="{}"/>"#,
            c.name(),
            e(c.description())
        );
    }
    let _ = writeln!(x, "  </LogCategories>");
    let d = M::DEFAULT_EXPERIMENT;
    let _ = writeln!(
        x,
        r#"  <DefaultExperiment startTime="{}" stopTime="{}" stepSize="{}"/>"#,
        real(d.start_time),
        real(d.stop_time),
        real(d.step_size)
    );
    let _ = writeln!(x, "  <ModelVariables>");
    for (i, v) in M::VARIABLES.iter().enumerate() {
        let initial = match v.causality {
            Causality::Parameter => r#" initial="exact""#,
            Causality::Output => r#" initial="calculated""#,
            Causality::Input => "",
        };
        let _ = writeln!(x, "    <!-- index {} -->", i + 1);
        let _ = writeln!(
            x,
            r#"    <ScalarVariable name="{}" valueReference="{}" description="{}" causality="{}" variability="{}"{initial}>"#,
            e(v.name),
            v.vr,
            e(v.description),
            v.causality.as_str(),
            v.variability.as_str()
        );
        let elem = match v.kind {
            Kind::Real {
                unit,
                start,
                min,
                max,
            } => {
                let mut a = String::new();
                if !unit.is_empty() {
                    let _ = write!(a, r#" unit="{}""#, e(unit));
                }
                if let Some(m) = min {
                    let _ = write!(a, r#" min="{}""#, real(m));
                }
                if let Some(m) = max {
                    let _ = write!(a, r#" max="{}""#, real(m));
                }
                if let Some(s) = start {
                    let _ = write!(a, r#" start="{}""#, real(s));
                }
                format!("<Real{a}/>")
            }
            Kind::Integer { start, min, max } => {
                let mut a = String::new();
                if let Some(m) = min {
                    let _ = write!(a, r#" min="{m}""#);
                }
                if let Some(m) = max {
                    let _ = write!(a, r#" max="{m}""#);
                }
                if let Some(s) = start {
                    let _ = write!(a, r#" start="{s}""#);
                }
                format!("<Integer{a}/>")
            }
            Kind::Enumeration { ty, start } => {
                format!(
                    r#"<Enumeration declaredType="{}" start="{start}"/>"#,
                    e(ty.name)
                )
            }
            Kind::Boolean { start } => format!(r#"<Boolean start="{start}"/>"#),
            Kind::String { start } => format!(r#"<String start="{}"/>"#, e(start)),
        };
        let _ = writeln!(x, "      {elem}");
        let _ = writeln!(x, "    </ScalarVariable>");
    }
    let _ = writeln!(x, "  </ModelVariables>");
    let _ = writeln!(x, "  <ModelStructure>");
    let outputs: Vec<usize> = M::VARIABLES
        .iter()
        .enumerate()
        .filter(|(_, v)| v.causality == Causality::Output)
        .map(|(i, _)| i + 1)
        .collect();
    let _ = writeln!(x, "    <Outputs>");
    for i in &outputs {
        let _ = writeln!(x, r#"      <Unknown index="{i}"/>"#);
    }
    let _ = writeln!(x, "    </Outputs>");
    let _ = writeln!(x, "    <InitialUnknowns>");
    for i in &outputs {
        let _ = writeln!(x, r#"      <Unknown index="{i}"/>"#);
    }
    let _ = writeln!(x, "    </InitialUnknowns>");
    let _ = writeln!(x, "  </ModelStructure>");
    let _ = writeln!(x, "</fmiModelDescription>");
    debug_assert!(M::VARIABLES
        .iter()
        .all(|v| v.variability != Variability::Continuous || matches!(v.kind, Kind::Real { .. })));
    x
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn escapes() {
        assert_eq!(
            escape_xml(r#"a<b & "c"'"#),
            "a&lt;b &amp; &quot;c&quot;&apos;"
        );
        assert_eq!(real(0.1), "0.1");
        assert_eq!(real(1.0), "1.0");
        assert_eq!(real(-2.5e-7), "-2.5e-7");
    }
}
