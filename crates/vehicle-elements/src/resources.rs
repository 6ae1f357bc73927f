//! Files an FMU of either model reads at initialisation, looked up where a host unpacked it.

use std::path::Path;

/// A file parameter as the FMU reads it: a relative name that names a file under the FMU's
/// `resources/` folder is taken from there (the shipped contact tables), anything else as
/// given.
pub fn resource_or_given(name: &str, resource_dir: Option<&Path>) -> String {
    if Path::new(name).is_relative() {
        if let Some(dir) = resource_dir {
            let candidate = dir.join(name);
            if candidate.is_file() {
                return candidate.to_string_lossy().into_owned();
            }
        }
    }
    name.to_string()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_shipped_name_resolves_under_resources_and_others_stay_as_given() {
        let dir = std::env::temp_dir().join(format!("vehicle-elements-res-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        std::fs::write(dir.join("table.csv"), "y").unwrap();
        let shipped = resource_or_given("table.csv", Some(&dir));
        assert_eq!(Path::new(&shipped), dir.join("table.csv"));
        assert_eq!(resource_or_given("other.csv", Some(&dir)), "other.csv");
        assert_eq!(resource_or_given("table.csv", None), "table.csv");
        let absolute = std::env::temp_dir().join("x.csv");
        let absolute = absolute.to_string_lossy();
        assert_eq!(resource_or_given(&absolute, Some(&dir)), absolute);
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
