//! The `fmuResourceLocation` of `fmi2Instantiate`: a `file:` URI naming the FMU's `resources/`
//! directory.
//!
//! Accepted forms: `file:///abs/path`, `file:/abs/path`, `file://localhost/abs/path`, with
//! percent-encoding (`%20`, `%25`, UTF-8 sequences) and with or without a trailing slash.
//! Remote hosts and other schemes are refused.

use std::path::PathBuf;

/// Turn a resource-location URI into a directory path; the error says what is wrong.
pub fn resource_dir_from_uri(uri: &str) -> Result<PathBuf, String> {
    let rest = uri
        .get(..5)
        .filter(|s| s.eq_ignore_ascii_case("file:"))
        .map(|_| &uri[5..])
        .ok_or_else(|| format!("resource location \"{uri}\" is not a file: URI"))?;
    let path = if let Some(authority_and_path) = rest.strip_prefix("//") {
        let slash = authority_and_path
            .find('/')
            .unwrap_or(authority_and_path.len());
        let (host, path) = authority_and_path.split_at(slash);
        if !(host.is_empty() || host.eq_ignore_ascii_case("localhost")) {
            return Err(format!(
                "resource location \"{uri}\" names the remote host \"{host}\""
            ));
        }
        path
    } else {
        rest
    };
    if !path.starts_with('/') {
        return Err(format!(
            "resource location \"{uri}\" does not hold an absolute path"
        ));
    }
    let mut decoded = percent_decode(path)
        .ok_or_else(|| format!("resource location \"{uri}\": bad percent-encoding"))?;
    while decoded.len() > 1 && decoded.ends_with('/') {
        decoded.pop();
    }
    Ok(PathBuf::from(decoded))
}

/// Decode `%XX` escapes; `None` on a malformed escape or a result that is not UTF-8.
pub fn percent_decode(s: &str) -> Option<String> {
    let bytes = s.as_bytes();
    let mut out = Vec::with_capacity(bytes.len());
    let mut i = 0;
    while i < bytes.len() {
        if bytes[i] == b'%' {
            let hex = bytes.get(i + 1..i + 3)?;
            let hex = std::str::from_utf8(hex).ok()?;
            out.push(u8::from_str_radix(hex, 16).ok()?);
            i += 3;
        } else {
            out.push(bytes[i]);
            i += 1;
        }
    }
    String::from_utf8(out).ok()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn ok(uri: &str) -> String {
        resource_dir_from_uri(uri).unwrap().display().to_string()
    }

    #[test]
    fn accepted_forms() {
        assert_eq!(ok("file:///tmp/fmu/resources"), "/tmp/fmu/resources");
        assert_eq!(ok("file:///tmp/fmu/resources/"), "/tmp/fmu/resources");
        assert_eq!(ok("file:/tmp/fmu/resources"), "/tmp/fmu/resources");
        assert_eq!(ok("file:/tmp/fmu/resources/"), "/tmp/fmu/resources");
        assert_eq!(ok("file://localhost/tmp/r"), "/tmp/r");
        assert_eq!(ok("FILE://LOCALHOST/tmp/r/"), "/tmp/r");
        assert_eq!(ok("file:///"), "/");
    }

    #[test]
    fn percent_decoding() {
        assert_eq!(ok("file:///tmp/a%20b/res"), "/tmp/a b/res");
        assert_eq!(ok("file:///tmp/100%25/res"), "/tmp/100%/res");
        assert_eq!(ok("file:///tmp/%C3%A9t%C3%A9"), "/tmp/été");
        assert!(resource_dir_from_uri("file:///tmp/%zz").is_err());
        assert!(resource_dir_from_uri("file:///tmp/%2").is_err());
        assert!(resource_dir_from_uri("file:///tmp/%FF").is_err());
    }

    #[test]
    fn refused_forms() {
        assert!(resource_dir_from_uri("http://example.com/r").is_err());
        assert!(resource_dir_from_uri("/tmp/plain/path").is_err());
        assert!(resource_dir_from_uri("file://server/share").is_err());
        assert!(resource_dir_from_uri("file:relative/path").is_err());
        assert!(resource_dir_from_uri("").is_err());
        assert!(resource_dir_from_uri("fi").is_err());
    }
}
