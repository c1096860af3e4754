//! The settings stage of a sweep: its config settled into a plan (the scheme as run, the
//! columns asked for), the engine chosen, the columns written and the fingerprint, with every
//! refusal the plan decides made before any file is.

use crate::engine::aggregate::Aggregator;
use crate::engine::gpu::GpuContext;
use crate::engine::{gpu_for, Engine, Kernel};
use crate::io::provenance::{Fingerprint, Meta, Settings, TargetError};
use crate::physics::solver::calibration::Choice;
use crate::plan::settings::{picked_columns, SchemeSettings};
use crate::plan::{config, Plan};
use crate::sweep::options::{Options, Said, SweepError};
use std::path::{Path, PathBuf};

/// A sweep ready to run: its plan, its engine's device, and how its runs are written.
pub struct Prepared {
    pub options: Options,
    /// The config's name, as messages give it (records are found from it).
    pub config: PathBuf,
    /// The config's text, read once (a record changed since is found from it).
    pub config_text: String,
    pub plan: Plan,
    /// The GPU the engine runs on, if any.
    gpu: Option<GpuContext>,
    /// `--target-error`'s choice.
    pub chosen: Option<Choice>,
    /// `--columns` as indices into the plan's header.
    pub picked: Option<Vec<usize>>,
    /// The names of the columns written (a row per run).
    pub names: Vec<String>,
    /// The summary the runs fold into (`--aggregate`); taken by the run.
    pub summary: Option<Aggregator>,
}

impl Prepared {
    /// Settle `options` on the config `config_text` (named `config`): the plan, the scheme
    /// as run (its notices and warnings to `say`), the GPU (its notices too), the engine, the
    /// columns and the summary, each checked.
    pub fn new(
        options: &Options,
        config: &Path,
        config_text: String,
        say: &mut dyn FnMut(Said),
    ) -> Result<Prepared, SweepError> {
        let mut plan = config::load_text(&config_text, config)?;
        let settled = SchemeSettings {
            scheme: options.scheme,
            energy: options.energy,
            target_error: options.target_error,
        }
        .settle(&mut plan, &config_text)?;
        for n in settled.notices {
            say(Said::Notice(n));
        }
        for w in settled.warnings {
            say(Said::Warning(format!("{}: {w}", config.display())));
        }
        plan.ask_columns(options.columns.as_deref().unwrap_or_default());
        let gpu = gpu_for(
            &plan,
            options.backend,
            options.precision,
            settled.chosen.is_some(),
            &mut |l| say(Said::Notice(l)),
        )?;
        let engine = Engine::new(
            plan.scheme(),
            gpu.as_ref(),
            options.precision,
            options.chunk,
        )?;
        let picked = picked_columns(&plan, options.columns.as_deref())?;
        let summary = options
            .aggregate
            .as_ref()
            .map(|by| Aggregator::for_plan(&plan, by, &options.exceed))
            .transpose()?;
        engine.check(&plan)?;
        Ok(Prepared {
            options: options.clone(),
            config: config.to_path_buf(),
            config_text,
            plan,
            gpu,
            chosen: settled.chosen,
            picked: picked.indices,
            names: picked.names,
            summary,
        })
    }

    /// The engine the sweep runs on (checked by [`Prepared::new`]).
    pub fn engine(&self) -> Engine<'_> {
        Engine::new(
            self.plan.scheme(),
            self.gpu.as_ref(),
            self.options.precision,
            self.options.chunk,
        )
        .expect("the engine was checked when the sweep was prepared")
    }

    /// What an output of the runs `runs` holds: the fingerprint, the engine and kernel, the
    /// columns where `--columns` chose them (None where a reader knows them: the pair's fixed
    /// schema, or a summary's), the setting `--target-error` chose and the plan's settings.
    pub fn meta(&self, runs: std::ops::Range<u64>) -> Meta {
        let fixed = self
            .names
            .iter()
            .map(String::as_str)
            .eq(crate::plan::columns::header());
        let named = self.options.aggregate.is_none() && !fixed;
        Meta {
            fingerprint: Fingerprint::of_plan(&self.plan),
            plan_runs: self.plan.len(),
            first_run: runs.start,
            end_run: runs.end,
            shard: self.options.shard,
            backend: self.engine().key(),
            kernel: Some(Kernel::of(&self.plan).key().into()),
            columns: named.then(|| self.names.clone()),
            content: None,
            target_error: self.chosen.map(TargetError::of),
            settings: Some(Settings::of_plan(&self.plan)),
        }
    }
}
