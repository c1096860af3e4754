//! The settings stage of a sweep, shared by `pound sweep` and the Python package: the scheme as
//! run (the config's, a scheme asked for, energy, `--target-error`'s choice from the scene's
//! calibration) and the columns written. Each returns the lines a user should hear, in order,
//! for the caller to show its own way (stderr, Python warnings).

use crate::physics::solver::calibration::{for_target_in, Choice, Suite};
use crate::physics::solver::{FastOptions, ReferenceOptions, Scheme};
use crate::plan::scene::Plan;

/// A scheme asked for over the config's.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SchemeKind {
    Fast,
    Reference,
}

/// A setting refused, in the command line's words.
#[derive(Debug, thiserror::Error)]
#[error("{0}")]
pub struct SettingsError(pub String);

/// What a sweep asks of its scheme on top of its config.
#[derive(Debug, Clone, Copy, Default)]
pub struct SchemeSettings {
    pub scheme: Option<SchemeKind>,
    /// Write each run's energy balance (the fast scheme; the reference always does).
    pub energy: bool,
    /// The relative error accepted: the fast scheme's cheapest calibrated setting within it.
    pub target_error: Option<f64>,
}

/// The scheme settled on a plan: `--target-error`'s choice, the notices said while choosing
/// and the plan's warnings at the setting run.
#[derive(Debug, Default)]
pub struct Settled {
    pub chosen: Option<Choice>,
    pub notices: Vec<String>,
    pub warnings: Vec<String>,
}

/// The scheme as run: the config's, or the one asked for (keeping the config's settings when it
/// names the same scheme), with `energy` added to the fast scheme.
pub fn scheme_as_run(configured: Scheme, asked: Option<SchemeKind>, energy: bool) -> Scheme {
    let scheme = match asked {
        None => configured,
        Some(SchemeKind::Fast) => Scheme::Fast(match configured {
            Scheme::Fast(o) => o,
            _ => FastOptions::default(),
        }),
        Some(SchemeKind::Reference) => Scheme::Reference(match configured {
            Scheme::Reference(o) => o,
            _ => ReferenceOptions::default(),
        }),
    };
    match scheme {
        Scheme::Fast(o) => Scheme::Fast(FastOptions {
            energy: o.energy || energy,
            ..o
        }),
        reference => reference,
    }
}

/// The cheapest calibrated accuracy setting of the fast scheme on `suite` whose error is at
/// most `target`, with the line that says it.
pub fn target_error_in(suite: Suite, target: f64) -> Result<(Choice, String), SettingsError> {
    if !(target > 0.0 && target.is_finite()) {
        return Err(SettingsError(format!(
            "--target-error {target}: expected a relative error above 0, e.g. 1e-2 ({})",
            suite.measure()
        )));
    }
    let c = for_target_in(suite, target).map_err(|best| {
        SettingsError(format!(
            "--target-error {target:e}: below what the fast scheme is calibrated for on {} (its smallest {} is {best:.1e}); use a larger target, or the reference scheme (pound sweep --scheme reference)",
            suite.config(),
            suite.measure()
        ))
    })?;
    let said = format!(
        "--target-error {target:e}: {} RK4 substeps per contact ({} {:.1e} on {}, measured by pound accuracy)",
        c.substeps_per_contact,
        suite.measure(),
        c.calibrated_p99,
        suite.config()
    );
    Ok((c, said))
}

impl SchemeSettings {
    /// Set the scheme as run on `plan` (the fingerprint covers it), `config_text` being the
    /// config's text (a `run.substeps_per_contact` that `target_error` replaces is said).
    pub fn settle(&self, plan: &mut Plan, config_text: &str) -> Result<Settled, SettingsError> {
        let mut settled = Settled::default();
        let mut scheme = scheme_as_run(plan.scheme(), self.scheme, self.energy);
        match (self.target_error, &mut scheme) {
            (None, _) => {}
            (Some(_), Scheme::Reference(_)) => {
                return Err(SettingsError(
                    "--target-error chooses the fast scheme's setting; the reference scheme is controlled by its tolerance (run.tol)".into(),
                ))
            }
            (Some(e), Scheme::Fast(o)) => {
                let (c, said) = target_error_in(plan.suite(), e)?;
                settled.notices.push(said);
                let given = config_text
                    .parse::<toml::Table>()
                    .ok()
                    .and_then(|t| t.get("run")?.get("substeps_per_contact").cloned());
                if let Some(v) = given {
                    settled.notices.push(format!(
                        "notice: --target-error overrides the config's run.substeps_per_contact = {v} with {}",
                        c.substeps_per_contact
                    ));
                }
                o.substeps_per_contact = c.substeps_per_contact;
                settled.chosen = Some(c);
            }
        }
        plan.set_scheme(scheme);
        let spc = match scheme {
            Scheme::Fast(o) => o.substeps_per_contact,
            Scheme::Reference(_) => FastOptions::default().substeps_per_contact,
        };
        settled.warnings = plan.warnings(spc);
        Ok(settled)
    }
}

/// The columns a sweep writes: `indices` into its plan's header (None: every column, in
/// order) and their `names`.
#[derive(Debug, Clone, PartialEq)]
pub struct Picked {
    pub indices: Option<Vec<usize>>,
    pub names: Vec<String>,
}

/// The columns `asked` (`--columns`) of `plan`, `run` first; every column without.
pub fn picked_columns(plan: &Plan, asked: Option<&[String]>) -> Result<Picked, SettingsError> {
    let header = plan.header();
    let Some(asked) = asked else {
        return Ok(Picked {
            indices: None,
            names: header,
        });
    };
    if let Some(twice) = crate::config::name_given_twice(asked) {
        return Err(SettingsError(format!(
            "--columns: `{twice}` is given twice: give each column once"
        )));
    }
    // A group (`+storeys`) adds its columns; groups alone add them to every column.
    use crate::plan::columns::row::{column_group, COLUMN_GROUPS};
    let (groups, names): (Vec<&String>, Vec<&String>) =
        asked.iter().partition(|c| c.starts_with('+'));
    for g in &groups {
        let known = COLUMN_GROUPS.iter().any(|(name, _)| name == g);
        let listed: Vec<String> = (COLUMN_GROUPS.iter())
            .map(|(name, what)| format!("{name} ({what})"))
            .collect();
        if !known {
            return Err(SettingsError(format!(
                "--columns: `{g}` is no column group: the groups are {}",
                listed.join(", ")
            )));
        }
        if let Plan::Pair(_) = plan {
            return Err(SettingsError(format!(
                "--columns: `{g}`: a pair's buildings have one storey each, whose peak displacements are its columns already (peak_u1_m, peak_u2_m); give the scene as a row of [[building]] sections for the groups {}",
                listed.join(", ")
            )));
        }
    }
    if names.is_empty() && !groups.is_empty() {
        return Ok(Picked {
            indices: None,
            names: header,
        });
    }
    let mut asked: Vec<String> = names.into_iter().cloned().collect();
    for c in &header {
        if (column_group(c)).is_some_and(|g| groups.iter().any(|x| x.as_str() == g))
            && !asked.contains(c)
        {
            asked.push(c.clone());
        }
    }
    let asked = &asked[..];
    let indices = crate::plan::columns::select_in(&header, asked).map_err(|bad| {
        SettingsError(format!(
            "--columns: `{bad}` is not a column of this sweep ({}); its columns are: {} (`pound columns CONFIG --all` lists them with their meanings, and the columns the + groups add)",
            plan.scene(),
            header.join(", ")
        ))
    })?;
    Ok(Picked {
        names: indices.iter().map(|&i| header[i].clone()).collect(),
        indices: Some(indices),
    })
}

/// Worker threads asked for (`--threads`), checked: 1 to [`MAX_THREADS`].
///
/// [`MAX_THREADS`]: crate::plan::limits::MAX_THREADS
pub fn check_threads(t: usize) -> Result<usize, SettingsError> {
    use crate::plan::limits::{MAX_THREADS, WHY_THREADS};
    if t == 0 || t > MAX_THREADS {
        return Err(SettingsError(format!(
            "--threads {t}: expected 1 to {MAX_THREADS} ({WHY_THREADS}; this machine has {})",
            std::thread::available_parallelism().map_or(1, |n| n.get())
        )));
    }
    Ok(t)
}

/// The warnings a finished sweep ends with: `above_height` runs had a building whose peak
/// displacement exceeds its height, `past_drift` a storey past the warning drift ratio.
pub fn sweep_warnings(plan: &Plan, above_height: u64, past_drift: u64) -> Vec<String> {
    let mut w = Vec::new();
    if above_height > 0 {
        w.push(format!("{above_height} runs have a building whose peak displacement exceeds its height ({}): check the record's units and the intensity", plan.height_basis()));
    }
    if past_drift > 0 {
        w.push(format!(
            "{past_drift} runs have a storey past a drift ratio of {} without collapsing (where collapse studies call a building collapsed): {}, so these buildings stand where real ones may have fallen; read them as collapsed, or as outside the model's range",
            crate::plan::limits::WARN_DRIFT_RATIO,
            match plan {
                Plan::Row(r) if r.collapse_drift_ratio.is_finite() => format!(
                    "the collapse limit is a drift ratio of {} ([run] collapse_drift_ratio)",
                    crate::show(r.collapse_drift_ratio)
                ),
                _ => "the collapse criterion is off ([run] collapse_drift_ratio = \"none\")".into(),
            }
        ));
    }
    w
}
