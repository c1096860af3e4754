//! The axes of a row that no run can use, refused once the row is decoded.

use crate::plan::axes::PlanError;
use crate::plan::row::{RowPlan, RowSampled};

impl RowPlan {
    /// Refuse every axis (a key of two values or more, or a sampled one) that cannot change a
    /// run of this row: it would repeat each run with the same physics, or be dropped, and a
    /// statistic over the runs would count each one as several. `contact_given`: the config
    /// has `[contact]`; `shared_values`: the values of `contact.gap_m` it gives. Err: the keys
    /// and why.
    pub(crate) fn refuse_idle_axes(
        &self,
        contact_given: bool,
        shared_values: usize,
    ) -> Result<(), (String, String)> {
        let nb = self.buildings.len();
        let c = &self.contact.spec;
        // Levels depend on the storeys and heights alone, which no axis sweeps.
        let levels = if nb > 1 { self.levels() } else { Vec::new() };
        let touching: Vec<bool> = (0..nb - 1)
            .map(|a| levels.iter().any(|l| l.left == a))
            .collect();
        let contact = touching.contains(&true);
        let sampled = |a: RowSampled| {
            (self.samples.iter())
                .flat_map(|s| s.axes.iter().position(|x| *x == a))
                .next()
        };
        // (key, values that multiply the runs, or 1 where they are dropped).
        let mut idle: Vec<(String, usize)> = Vec::new();
        let mut idle_sampled: Vec<String> = Vec::new();
        if !contact && contact_given {
            let repeated = self.contact.len() as usize / (c.records.len() * c.intensities.len());
            for (key, n) in [
                ("contact.law", c.laws.len()),
                ("contact.formula", c.formulas.len()),
                ("contact.e", c.e.len()),
                ("contact.k_n_per_m", c.k_linear.len()),
                ("contact.beta_n_per_m1_5", c.beta.len()),
            ] {
                if n > 1 {
                    idle.push((key.into(), 1));
                }
            }
            if let Some((_, n)) = idle.first_mut() {
                *n = repeated;
            }
            for a in [RowSampled::KLinear, RowSampled::Beta] {
                if let Some(j) = sampled(a) {
                    idle_sampled.push(format!("sample.axis[{j}] ({})", a.key()));
                }
            }
        }
        if nb == 1 {
            if let Some(j) = sampled(RowSampled::SharedGap) {
                idle_sampled.push(format!("sample.axis[{j}] (contact.gap_m)"));
            }
        }
        // Each gap axis: its own pair's, or `contact.gap_m` for every pair it gives.
        for a in 0..nb - 1 {
            if self.gap_axis[a] != a {
                continue;
            }
            let readers: Vec<usize> = (0..nb - 1).filter(|&p| self.gap_axis[p] == a).collect();
            if readers.iter().any(|&p| touching[p]) {
                continue;
            }
            let key = if self.shared_gap[a] {
                "contact.gap_m".to_string()
            } else {
                format!("building[{a}].gap_right_m")
            };
            let axis = if self.shared_gap[a] {
                RowSampled::SharedGap
            } else {
                RowSampled::Gap(a)
            };
            match sampled(axis) {
                Some(j) => idle_sampled.push(format!("sample.axis[{j}] ({key})")),
                None if self.gaps[a].len() > 1 => idle.push((key, self.gaps[a].len())),
                None => {}
            }
        }
        // A shared gap list no pair reads (a building alone, or every pair with its own).
        let dropped_shared = shared_values > 1 && !self.shared_gap.contains(&true);
        if dropped_shared {
            idle.push(("contact.gap_m".into(), 1));
        }
        if idle.is_empty() && idle_sampled.is_empty() {
            return self
                .refuse_unused_by_laws(contact)
                .map_err(|e| (e.key, e.message));
        }
        let samples = self.samples.as_ref().map_or(1, |s| s.points.len());
        let all_sampled_idle = self
            .samples
            .as_ref()
            .is_some_and(|s| s.axes.len() == idle_sampled.len());
        let repeat: usize = idle.iter().map(|(_, n)| n).product::<usize>()
            * if all_sampled_idle { samples } else { 1 };
        let keys: Vec<String> = idle
            .iter()
            .map(|(k, _)| k.clone())
            .chain(idle_sampled)
            .collect();
        let why = if nb == 1 {
            "a building alone has no contact".to_string()
        } else if !contact {
            "no two neighbours share a contact level (no floor at a common elevation, and [levels] floor_column = false), so no run has contact".to_string()
        } else if dropped_shared && keys.len() == 1 && keys[0] == "contact.gap_m" {
            "every pair has its own gap_right_m, so no pair reads contact.gap_m".to_string()
        } else {
            let apart: Vec<String> = (0..nb - 1)
                .filter(|&a| !touching[a])
                .map(|a| format!("buildings {} and {}", a + 1, a + 2))
                .collect();
            format!(
                "{} share no contact level (no floor at a common elevation, and [levels] floor_column = false), so their gap is never checked",
                apart.join(", ")
            )
        };
        let (this, it) = if keys.len() == 1 {
            ("this axis", "it")
        } else {
            ("these axes", "them")
        };
        let effect = if repeat > 1 {
            format!("{this} would repeat each run {repeat} times with the same physics")
        } else {
            format!("{this} cannot change a run (the values would be dropped)")
        };
        let remedy = if nb == 1 {
            "add a second [[building]]"
        } else if dropped_shared && keys.len() == 1 {
            "give the gaps in one place"
        } else {
            "give the buildings a common floor level or [levels] floor_column = true"
        };
        Err((
            keys.join(", "),
            format!("{why}: {effect}; remove {it} or {remedy}"),
        ))
    }

    /// Where some pair has contact: refuse the contact axes and sampled stiffnesses that no
    /// law given takes ([`crate::plan::ContactSpec::refuse_unused`]).
    fn refuse_unused_by_laws(&self, contact: bool) -> Result<(), PlanError> {
        if !contact {
            return Ok(());
        }
        let spec = &self.contact.spec;
        spec.refuse_unused()?;
        for (j, a) in self.samples.iter().flat_map(|s| s.axes.iter().enumerate()) {
            if matches!(a, RowSampled::KLinear | RowSampled::Beta) {
                spec.refuse_unused_sample(j, &a.key())?;
            }
        }
        Ok(())
    }
}
