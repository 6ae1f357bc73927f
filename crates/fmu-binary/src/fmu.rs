//! Check every binary of an `.fmu` file against its `modelDescription.xml`.

use std::collections::BTreeMap;
use std::io::Read;
use std::path::{Path, PathBuf};

use crate::inspect::{inspect, BinaryInfo};
use crate::platform::Platform;
use crate::policy::{check_binary, Policy, Problem};
use crate::version::SymbolVersion;
use crate::{FMI2_COMMON_FUNCTIONS, FMI2_COSIMULATION_FUNCTIONS, FMI2_MODEL_EXCHANGE_FUNCTIONS};

#[derive(Debug, thiserror::Error)]
pub enum FmuError {
    #[error("{path}: {source}")]
    Io {
        path: PathBuf,
        source: std::io::Error,
    },
    #[error("{path}: not a readable FMU archive: {source}")]
    Zip {
        path: PathBuf,
        source: zip::result::ZipError,
    },
    #[error("{path}: modelDescription.xml: {reason}")]
    ModelDescription { path: PathBuf, reason: String },
}

/// One file under `binaries/` (or one that should be there).
#[derive(Debug, Clone)]
pub struct FmuBinaryReport {
    /// Path inside the FMU, e.g. `binaries/linux64/Bogie2Dof.so`.
    pub entry: String,
    /// `None` for a folder that is no known platform.
    pub platform: Option<Platform>,
    /// The model identifier whose binary this is; `None` for another library in the folder
    /// (a dependency), which is checked for format, architecture and the Linux rules only.
    pub model_identifier: Option<String>,
    /// `None` when the file is missing or cannot be read.
    pub info: Option<BinaryInfo>,
    pub problems: Vec<Problem>,
}

/// Result of [`check_fmu`].
#[derive(Debug, Clone)]
pub struct FmuReport {
    pub path: PathBuf,
    /// `modelIdentifier` of each interface type the FMU declares, with the functions it needs.
    pub model_identifiers: Vec<String>,
    pub binaries: Vec<FmuBinaryReport>,
}

impl FmuReport {
    /// True when the FMU carries at least one model binary and nothing has a problem.
    pub fn is_ok(&self) -> bool {
        self.binaries.iter().any(|b| b.model_identifier.is_some())
            && self.binaries.iter().all(|b| b.problems.is_empty())
    }

    /// The newest glibc any Linux binary of the FMU needs (the oldest glibc it loads on).
    pub fn newest_glibc(&self) -> Option<SymbolVersion> {
        self.binaries
            .iter()
            .filter_map(|b| b.info.as_ref()?.newest_glibc())
            .max()
    }

    /// The platform folders that hold a model binary.
    pub fn platforms(&self) -> Vec<Platform> {
        let mut p: Vec<Platform> = self
            .binaries
            .iter()
            .filter(|b| b.model_identifier.is_some() && b.info.is_some())
            .filter_map(|b| b.platform)
            .collect();
        p.sort();
        p.dedup();
        p
    }
}

/// The model identifiers of an FMI 2.0 `modelDescription.xml`, each with the functions its
/// binary must export (common + co-simulation and/or model exchange).
pub fn required_functions(xml: &str) -> Result<BTreeMap<String, Vec<&'static str>>, String> {
    let doc = roxmltree::Document::parse(xml).map_err(|e| e.to_string())?;
    let root = doc.root_element();
    if root.tag_name().name() != "fmiModelDescription" {
        return Err(format!(
            "root element is <{}>, not <fmiModelDescription>",
            root.tag_name().name()
        ));
    }
    let version = root.attribute("fmiVersion").unwrap_or("");
    if !version.starts_with("2.") {
        return Err(format!(
            "fmiVersion '{version}': only FMI 2.0 binaries are checked"
        ));
    }
    let mut out: BTreeMap<String, Vec<&'static str>> = BTreeMap::new();
    for node in root.children().filter(|n| n.is_element()) {
        let specific: &[&'static str] = match node.tag_name().name() {
            "CoSimulation" => &FMI2_COSIMULATION_FUNCTIONS,
            "ModelExchange" => &FMI2_MODEL_EXCHANGE_FUNCTIONS,
            _ => continue,
        };
        let id = node
            .attribute("modelIdentifier")
            .ok_or_else(|| format!("<{}> has no modelIdentifier", node.tag_name().name()))?;
        let functions = out.entry(id.to_string()).or_default();
        if functions.is_empty() {
            functions.extend_from_slice(&FMI2_COMMON_FUNCTIONS);
        }
        functions.extend_from_slice(specific);
    }
    if out.is_empty() {
        return Err("neither <CoSimulation> nor <ModelExchange> is declared".into());
    }
    Ok(out)
}

/// Read the FMU at `path` and check every file under `binaries/`: known platform folder,
/// each model identifier's binary present in every platform folder that has one, the right
/// format and architecture, the FMI 2.0 functions exported, and `policy`'s Linux rules.
pub fn check_fmu(path: &Path, policy: &Policy) -> Result<FmuReport, FmuError> {
    let file = std::fs::File::open(path).map_err(|source| FmuError::Io {
        path: path.to_path_buf(),
        source,
    })?;
    let zip_err = |source| FmuError::Zip {
        path: path.to_path_buf(),
        source,
    };
    let mut archive = zip::ZipArchive::new(file).map_err(zip_err)?;
    let md_err = |reason: String| FmuError::ModelDescription {
        path: path.to_path_buf(),
        reason,
    };
    let xml = {
        let mut entry = archive
            .by_name("modelDescription.xml")
            .map_err(|e| md_err(e.to_string()))?;
        let mut s = String::new();
        entry
            .read_to_string(&mut s)
            .map_err(|e| md_err(e.to_string()))?;
        s
    };
    let required = required_functions(&xml).map_err(md_err)?;

    let names: Vec<String> = archive.file_names().map(String::from).collect();
    let mut binaries = Vec::new();
    let mut found: BTreeMap<Platform, Vec<String>> = BTreeMap::new();
    for name in names {
        let Some(rest) = name.strip_prefix("binaries/") else {
            continue;
        };
        let Some((folder, file_name)) = rest.split_once('/') else {
            continue;
        };
        if file_name.is_empty() || file_name.contains('/') {
            continue;
        }
        let Some(platform) = Platform::from_folder(folder) else {
            binaries.push(FmuBinaryReport {
                entry: name.clone(),
                platform: None,
                model_identifier: None,
                info: None,
                problems: vec![Problem::UnknownPlatform(folder.to_string())],
            });
            continue;
        };
        let Some(stem) = file_name.strip_suffix(&format!(".{}", platform.extension())) else {
            continue;
        };
        let model_identifier = required.contains_key(stem).then(|| stem.to_string());
        let exports: &[&str] = match &model_identifier {
            Some(id) => required.get(id).map(Vec::as_slice).unwrap_or(&[]),
            None => &[],
        };
        let mut bytes = Vec::new();
        let read = archive.by_name(&name).map_err(zip_err).and_then(|mut e| {
            e.read_to_end(&mut bytes).map_err(|source| FmuError::Io {
                path: path.to_path_buf(),
                source,
            })
        });
        read?;
        let (info, problems) = match inspect(&bytes) {
            Ok(info) => {
                let problems = check_binary(&info, platform, exports, policy);
                (Some(info), problems)
            }
            Err(e) => (None, vec![Problem::Unreadable(e.to_string())]),
        };
        if let Some(id) = &model_identifier {
            found.entry(platform).or_default().push(id.clone());
        }
        binaries.push(FmuBinaryReport {
            entry: name,
            platform: Some(platform),
            model_identifier,
            info,
            problems,
        });
    }
    for (platform, ids) in &found {
        for id in required.keys().filter(|id| !ids.contains(id)) {
            let file = platform.library_file_name(id);
            binaries.push(FmuBinaryReport {
                entry: format!("binaries/{platform}/{file}"),
                platform: Some(*platform),
                model_identifier: Some(id.clone()),
                info: None,
                problems: vec![Problem::MissingBinary {
                    platform: *platform,
                    file,
                }],
            });
        }
    }
    binaries.sort_by(|a, b| a.entry.cmp(&b.entry));
    Ok(FmuReport {
        path: path.to_path_buf(),
        model_identifiers: required.into_keys().collect(),
        binaries,
    })
}
