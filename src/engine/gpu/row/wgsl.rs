//! The row's shape written as WGSL for `shaders/row.wgsl`: its constants and layout, and
//! for a small row its per-shape functions written out (taller rows take
//! `shaders/row_loops.wgsl`).

// Every offset of the layout is written out as a WGSL constant.
use super::shape::*;
use crate::engine::gpu::layout::STATUS_COLLAPSE;
use crate::engine::gpu::shader::{for_imk, ROW_LOOPS_WGSL};

/// The most `sum n^2` over a row's buildings whose per-shape functions are written out
/// ([`RowShape::unrolled`]).
pub const UNROLL_MAX_SQUARES: usize = 65;

impl RowShape {
    /// The shape and layout as WGSL constants, prepended to `row.wgsl`.
    pub fn wgsl_constants(&self) -> String {
        let list = |v: &[usize]| -> String {
            let items: Vec<String> = v.iter().map(|x| format!("{x}u")).collect();
            items.join(", ")
        };
        let nb = self.storeys.len();
        let nl = self.levels.len();
        let nla = nl.max(1);
        let offs = self.mode_offsets();
        let pick = |k: usize| -> Vec<usize> {
            let v: Vec<usize> = self.levels.iter().map(|l| l[k]).collect();
            if v.is_empty() {
                vec![0]
            } else {
                v
            }
        };
        let mut s = String::new();
        let mut c = |name: &str, v: usize| s.push_str(&format!("const {name}: u32 = {v}u;\n"));
        let ns = self.yielding_storeys();
        c("NB", nb);
        c("NM", self.modes());
        c("NL", nl);
        c("NLA", nla);
        c("NCA", self.columns.len().max(1));
        c("NS", ns);
        c("NSA", ns.max(1));
        c("PS0", self.plastic_slot0());
        c("ZLEN", self.zlen());
        c("MAXN", *self.storeys.iter().max().unwrap_or(&1));
        c("FLEN", 10 * self.modes());
        c("MW", MW);
        for (name, v) in [
            ("P_DT", P_DT),
            ("P_T0", P_T0),
            ("P_SCALE", P_SCALE),
            ("P_PER_CONTACT", P_PER_CONTACT),
            ("P_STIFFNESS", P_STIFFNESS),
            ("P_RATIO", P_RATIO),
            ("P_RATE", P_RATE),
            ("P_COLLAPSE", P_COLLAPSE),
            ("P_GAPS", P_GAPS),
            ("P_LEVELS", P_GAPS + nb - 1),
            ("LEVEL_PARAMS", LEVEL_PARAMS),
            ("P_COLUMNS", self.p_columns()),
            ("P_STRIDE", self.p_stride()),
            ("M_LAW", M_LAW),
            ("M_REC_OFFSET", M_REC_OFFSET),
            ("M_REC_LEN", M_REC_LEN),
            ("M_INTERVALS", M_INTERVALS),
            ("M_MODELS", M_MODELS),
            ("M_SETTLE_END", M_MODELS + nb),
            ("M_STRIDE", self.m_stride()),
            ("C_STATUS", C_STATUS),
            ("STATUS_COLLAPSE", STATUS_COLLAPSE as usize),
            ("C_SUBSTEPS", C_SUBSTEPS),
            ("C_I", C_I),
            ("C_J", C_J),
            ("C_M", C_M),
            ("C_PIECES", C_PIECES),
            ("C_FREE_STEPS", C_FREE_STEPS),
            ("C_LOCATE", C_LOCATE),
            ("C_LEVELS", C_LEVELS),
            ("C_BUILDINGS", self.c_buildings()),
            ("C_SETTLED", self.c_settled()),
            ("C_STOREYS", self.c_storeys()),
            ("SC_MODE", SC_MODE),
            ("SC_YIELDED", SC_YIELDED),
            ("SC_FIRE", SC_FIRE),
            ("SC_STRIDE", SC_STRIDE),
            ("STOREY_HEAD", STOREY_HEAD),
            ("C_STRIDE", self.c_stride()),
            ("LC_MODE", LC_MODE),
            ("LC_IMPACTS", LC_IMPACTS),
            ("LC_I_ONSET", LC_I_ONSET),
            ("LC_FIRE", LC_FIRE),
            ("LC_STRIDE", LC_STRIDE),
            ("BC_DRIFT_STOREY", BC_DRIFT_STOREY),
            ("BC_ACCEL_FLOOR", BC_ACCEL_FLOOR),
            ("BC_STRIDE", BC_STRIDE),
            ("S_TAU", self.zlen()),
            ("S_LOCATE", self.s_locate()),
            ("S_LEVELS", self.s_levels()),
            ("S_BUILDINGS", self.s_buildings()),
            ("S_STOREYS", self.s_storeys()),
            ("S_STRIDE", self.s_stride()),
            ("LS_V0", LS_V0),
            ("LS_TAU_ONSET", LS_TAU_ONSET),
            ("LS_IMP_PEAK", LS_IMP_PEAK),
            ("LS_PEAK_FORCE", LS_PEAK_FORCE),
            ("LS_IMPACT_VELOCITY", LS_IMPACT_VELOCITY),
            ("LS_PENETRATION", LS_PENETRATION),
            ("LS_FIRST_IMPACT", LS_FIRST_IMPACT),
            ("LS_CONTACT_TIME", LS_CONTACT_TIME),
            ("LS_DISSIPATED", LS_DISSIPATED),
            ("LS_COLUMN_SHEAR", LS_COLUMN_SHEAR),
            ("LS_STRIDE", LS_STRIDE),
            ("BS_ROOF", BS_ROOF),
            ("BS_DRIFT", BS_DRIFT),
            ("BS_ACCEL", BS_ACCEL),
            ("BS_STRIDE", BS_STRIDE),
        ] {
            c(name, v);
        }
        // Private arrays, not `const` ones: they are indexed at run time.
        let mut a = |name: &str, len: &str, v: &[usize]| {
            s.push_str(&format!(
                "var<private> {name}: array<u32, {len}> = array<u32, {len}>({});\n",
                list(v)
            ))
        };
        a("B_N", "NB", &self.storeys);
        a("B_OFF", "NB", &offs);
        a("L_A", "NLA", &pick(0));
        a("L_FA", "NLA", &pick(1));
        a("L_FB", "NLA", &pick(2));
        // Where floors strike columns: each level's struck side (2: none) and its index among
        // such levels, each side's weight (1 on a floor).
        let (mut struck, mut index) = (vec![2; nla], vec![0; nla]);
        for (i, &(l, side, _)) in self.columns.iter().enumerate() {
            (struck[l], index[l]) = (side, i);
        }
        a("L_CS", "NLA", &struck);
        a("L_CI", "NLA", &index);
        let mut weights = String::new();
        for (name, side) in [("L_WA", 0), ("L_WB", 1)] {
            let w: Vec<String> = (0..nla)
                .map(|l| format!("{:?}", self.weight(l, side)))
                .collect();
            weights.push_str(&format!(
                "var<private> {name}: array<real, NLA> = array<real, NLA>({});\n",
                w.join(", ")
            ));
        }
        // The yielding storeys: each one's building and storey, each building's first (NS
        // where it is elastic).
        let firsts = self.first_storeys();
        let first: Vec<usize> = firsts.iter().map(|f| f.unwrap_or(ns)).collect();
        let (mut sb, mut sj) = (Vec::new(), Vec::new());
        for (b, (&n, f)) in self.storeys.iter().zip(&firsts).enumerate() {
            if f.is_some() {
                sb.extend(std::iter::repeat_n(b, n));
                sj.extend(0..n);
            }
        }
        if ns == 0 {
            (sb, sj) = (vec![0], vec![0]);
        }
        a("S_B", "NSA", &sb);
        a("S_J", "NSA", &sj);
        a("B_S0", "NB", &first);
        // Where each building's coupled part starts in its block (0: its modes are uncoupled).
        let cp: Vec<usize> = (self.storeys.iter().zip(&self.yielding).zip(&self.coupled))
            .map(|((&n, &y), &c)| if c { Self::model_head_len(n, y) } else { 0 })
            .collect();
        a("B_CP", "NB", &cp);
        s.push_str(&weights);
        s.push_str(&format!(
            "const COUPLED: bool = {};\nconst HAS_COLUMNS: bool = {};\n",
            self.coupled.iter().any(|&c| c),
            !self.columns.is_empty()
        ));
        if self.has_imk() {
            s.push_str(&self.wgsl_imk());
        }
        s.push_str(&self.wgsl_collapse_reached());
        if self.unrolled() {
            s.push_str(&self.wgsl_unrolled());
        } else {
            s.push_str(&for_imk(ROW_LOOPS_WGSL, self.has_imk()));
        }
        s
    }

    /// A row with IMK storeys: where their parameters, state and counters are
    /// (`shaders/imk.wgsl`), and which yielding storeys are IMK springs.
    fn wgsl_imk(&self) -> String {
        let mut s = String::new();
        for (name, v) in [
            ("IMK_PARAMS", IMK_PARAMS),
            ("S_IMK", self.s_imk()),
            ("IS_STRIDE", IS_STRIDE),
            ("C_IMK", self.c_imk()),
            ("IC_STRIDE", IC_STRIDE),
        ] {
            s.push_str(&format!("const {name}: u32 = {v}u;\n"));
        }
        let at: Vec<String> = (self.storeys.iter().zip(&self.yielding).zip(&self.coupled))
            .map(|((&n, &y), &c)| format!("{}u", Self::model_coupled_len(n, y, c)))
            .collect();
        let is: Vec<&str> = (self.storeys.iter().zip(&self.imk).zip(&self.yielding))
            .filter(|(_, &y)| y)
            .flat_map(|((&n, &i), _)| std::iter::repeat_n(if i { "true" } else { "false" }, n))
            .collect();
        s.push_str(&format!(
            "var<private> IMK_AT: array<u32, NB> = array<u32, NB>({});\nvar<private> IS_IMK: array<bool, NSA> = array<bool, NSA>({});\n",
            at.join(", "),
            is.join(", ")
        ));
        s
    }

    /// `collapse_reached()`: has a building's peak drift ratio reached the run's collapse
    /// limit (the host's test of a run's output, `!(peak < limit)`, so that a NaN peak ends it
    /// too)? Written out per building: no loop, so the loop trips per unit stay as counted.
    fn wgsl_collapse_reached(&self) -> String {
        let mut e = String::from("false");
        for b in 0..self.storeys.len() {
            e.push_str(&format!(
                " || !(rstate[RS + S_BUILDINGS + {}u] < limit)",
                BS_STRIDE * b + BS_DRIFT
            ));
        }
        format!("fn collapse_reached() -> bool {{\n    let limit = rp(P_COLLAPSE);\n    return {e};\n}}\n")
    }

    /// Is the row small enough to write its per-shape functions out (`wgsl_unrolled`)? The
    /// written-out floors grow as the square of a building's storeys, and lavapipe's compile
    /// time faster still; taller rows take `shaders/row_loops.wgsl`.
    pub fn unrolled(&self) -> bool {
        self.storeys.iter().map(|n| n * n).sum::<usize>() <= UNROLL_MAX_SQUARES
    }

    /// Where each building's modes start in the state (`B_OFF`).
    fn mode_offsets(&self) -> Vec<usize> {
        (self.storeys.iter())
            .scan(0, |o, &n| {
                let at = *o;
                *o += n;
                Some(at)
            })
            .collect()
    }

    /// The row's per-shape functions (`row::rhs`, each level's gap, rate, bound and structural
    /// acceleration, the floors' `fill`, a storey's drift, the plastic loads) written out for
    /// this shape, with what they read per run cached where every index is a constant (each
    /// building's mode shapes and masses in `SHP`, each coupled building's `E` in `CPE`, each
    /// yielding storey's row in `STR`, loaded by `load_shape_rows`).
    /// lavapipe turns a private array indexed at run time into a per-lane loop of loads and
    /// stores; written out, the state's indices are constants and its reals stay in
    /// registers. The operations and their order are those of the loops this replaces
    /// (`side_of`, `force`, `coupled_term`), so the values are the same.
    fn wgsl_unrolled(&self) -> String {
        let nm = self.modes();
        let offs = self.mode_offsets();
        let mut s = String::new();
        let mut load = String::new();
        // Each building's mode shapes (floor-major) and floor masses, for `fill`.
        let mut shp = Vec::new();
        let mut nshp = 0;
        for (b, &n) in self.storeys.iter().enumerate() {
            shp.push(nshp);
            for x in 0..n * n + n {
                load.push_str(&format!(
                    "    SHP[{}u] = models[MB[{b}u] + {}u];\n",
                    nshp + x,
                    MW * n + x
                ));
            }
            nshp += n * n + n;
        }
        // Each level's two sides' rows of mode shapes: where their n reals start in SHP (a
        // floor's row, or on a column its storey's floors' rows by their shares, as
        // `BuildingModel::point_row`).
        let mut rows: Vec<[usize; 2]> = Vec::new();
        for (l, &[a, fa, fb]) in self.levels.iter().enumerate() {
            let mut pair = [0; 2];
            for (side, (b, f)) in [(a, fa), (a + 1, fb)].into_iter().enumerate() {
                let n = self.storeys[b];
                let row = |f: usize| shp[b] + f * n;
                let w = self.weight(l, side);
                if w == 1.0 {
                    pair[side] = row(f);
                    continue;
                }
                pair[side] = nshp;
                for i in 0..n {
                    let top = format!("{:?} * SHP[{}u]", w, row(f) + i);
                    let x = if f == 0 {
                        top
                    } else {
                        format!("{:?} * SHP[{}u] + {top}", 1.0 - w, row(f - 1) + i)
                    };
                    load.push_str(&format!("    SHP[{}u] = {x};\n", nshp + i));
                }
                nshp += n;
            }
            rows.push(pair);
        }
        let mut cpe = Vec::new();
        let mut ncpe = 0;
        for (b, &n) in self.storeys.iter().enumerate() {
            if self.coupled[b] {
                cpe.push((b, ncpe));
                for i in 0..n {
                    for k in 0..n {
                        load.push_str(&format!(
                            "    CPE[{}u] = cpl_e({b}u, {i}u, {k}u);\n",
                            ncpe + n * i + k
                        ));
                    }
                }
                ncpe += n * n;
            }
        }
        // Each yielding storey's modal row (`st_row`), for its drift and plastic load.
        let mut str_at = Vec::new();
        let mut nstr = 0;
        let mut st = 0;
        for (b, (&n, &y)) in self.storeys.iter().zip(&self.yielding).enumerate() {
            if !y {
                continue;
            }
            for _ in 0..n {
                str_at.push((b, nstr));
                for i in 0..n {
                    load.push_str(&format!("    STR[{}u] = st_row({st}u, {i}u);\n", nstr + i));
                }
                nstr += n;
                st += 1;
            }
        }
        s.push_str(&format!(
            "var<private> STR: array<real, {}>;\n",
            nstr.max(1)
        ));
        s.push_str(&format!(
            "var<private> CPE: array<real, {}>;\nvar<private> SHP: array<real, {nshp}>;\n",
            ncpe.max(1)
        ));
        s.push_str("fn load_shape_rows() {\n");
        s.push_str(&load);
        s.push_str("}\n");
        // phi . q of a side row from offset `at` of z (side_of).
        let dot = |row: usize, b: usize, at: usize| -> String {
            let mut e = String::from("0.0");
            for i in 0..self.storeys[b] {
                e.push_str(&format!(
                    " + SHP[{}u] * (*z)[{}u]",
                    row + i,
                    at + offs[b] + i
                ));
            }
            e
        };
        // Each level's gap and its rate (row/mod.rs LevelModel), a case per level.
        for (name, at, gap) in [("delta", 0, true), ("ddelta", nm, false)] {
            s.push_str(&format!(
                "fn {name}(l: u32, z: ptr<function, ZA>) -> real {{\n    switch l {{\n"
            ));
            for (l, (&[a, _, _], &[ra, rb])) in self.levels.iter().zip(&rows).enumerate() {
                let gap = if gap {
                    format!(" - rp(P_GAPS + {a}u)")
                } else {
                    String::new()
                };
                s.push_str(&format!(
                    "        case {l}u: {{ return ({}) - ({}){gap}; }}\n",
                    dot(ra, a, at),
                    dot(rb, a + 1, at)
                ));
            }
            s.push_str("        default: { return 0.0; }\n    }\n}\n");
        }
        // (E q')_i of coupled building b whose E starts at c in CPE (row.wgsl's coupled_term).
        let coupled_term = |b: usize, c: usize, i: usize| -> String {
            let n = self.storeys[b];
            let mut e = String::from("0.0");
            for k in 0..n {
                e.push_str(&format!(
                    " + CPE[{}u] * (*z)[{}u]",
                    c + n * i + k,
                    nm + offs[b] + k
                ));
            }
            e
        };
        let cpe_of = |b: usize| cpe.iter().find(|(x, _)| *x == b).map(|&(_, c)| c);
        // Each level's bound (its floors' mode shapes by the modes' bounds QB) and its floors'
        // structural relative acceleration (row_loops.wgsl's level_bound, floor_accel).
        s.push_str("fn level_bound(l: u32) -> real {\n    switch l {\n");
        for (l, (&[a, _, _], &[ra, rb])) in self.levels.iter().zip(&rows).enumerate() {
            let side = |row: usize, b: usize| -> String {
                let mut e = String::from("0.0");
                for i in 0..self.storeys[b] {
                    e.push_str(&format!(" + abs(SHP[{}u]) * QB[{}u]", row + i, offs[b] + i));
                }
                e
            };
            s.push_str(&format!(
                "        case {l}u: {{ return ({}) + ({}); }}\n",
                side(ra, a),
                side(rb, a + 1)
            ));
        }
        s.push_str("        default: { return 0.0; }\n    }\n}\n");
        s.push_str(
            "fn structural_rel_accel(l: u32, z: ptr<function, ZA>) -> real {\n    switch l {\n",
        );
        for (l, (&[a, _, _], &[ra, rb])) in self.levels.iter().zip(&rows).enumerate() {
            s.push_str(&format!("        case {l}u: {{\n"));
            for (name, row, b) in [("sa", ra, a), ("sb", rb, a + 1)] {
                let mut e = String::from("0.0");
                for i in 0..self.storeys[b] {
                    let k = offs[b] + i;
                    e.push_str(&format!(
                        " + SHP[{}u] * (-TXW[{k}u] * (*z)[{}u] - W2[{k}u] * (*z)[{k}u])",
                        row + i,
                        nm + k
                    ));
                }
                s.push_str(&format!("            var {name} = {e};\n"));
                if let Some(c) = cpe_of(b) {
                    s.push_str(&format!("            if (coupled({b}u)) {{\n"));
                    for i in 0..self.storeys[b] {
                        s.push_str(&format!(
                            "                {name} -= SHP[{}u] * ({});\n",
                            row + i,
                            coupled_term(b, c, i)
                        ));
                    }
                    s.push_str("            }\n");
                }
            }
            s.push_str("            return sa - sb;\n        }\n");
        }
        s.push_str("        default: { return 0.0; }\n    }\n}\n");
        // Floors::fill of building b at end e (row.wgsl's `fill`), a case per building.
        s.push_str("fn fill(b: u32, e: u32, z: ptr<function, ZA>, ag: real) {\n    var acc: array<real, MAXN>;\n    var jrk: array<real, MAXN>;\n    switch b {\n");
        for (b, &n) in self.storeys.iter().enumerate() {
            let o = offs[b];
            s.push_str(&format!("        case {b}u: {{\n            let yields = NS > 0u && B_S0[{b}u] < NS;\n            if (yields) {{ plastic_loads({b}u, z); }}\n"));
            for i in 0..n {
                let k = o + i;
                s.push_str(&format!(
                    "            {{\n                var a = -TXW[{k}u] * (*z)[{v}u] - W2[{k}u] * (*z)[{k}u];\n                if (yields) {{ a += PLA[{i}u]; }}\n                acc[{i}u] = a;\n                let qdd = a - PART[{k}u] * ag;\n                jrk[{i}u] = -TXW[{k}u] * qdd - W2[{k}u] * (*z)[{v}u];\n                if (yields) {{ jrk[{i}u] += PLJ[{i}u]; }}\n            }}\n",
                    v = nm + k
                ));
            }
            if let Some(c) = cpe_of(b) {
                s.push_str(&format!("            if (coupled({b}u)) {{\n"));
                for i in 0..n {
                    let e = coupled_term(b, c, i);
                    s.push_str(&format!(
                        "                {{\n                    let ev = {e};\n                    acc[{i}u] -= ev;\n                    jrk[{i}u] += TXW[{}u] * ev;\n                }}\n",
                        o + i
                    ));
                }
                for i in 0..n {
                    let mut e = String::from("0.0");
                    for k in 0..n {
                        e.push_str(&format!(
                            " + CPE[{}u] * (acc[{k}u] - PART[{}u] * ag)",
                            c + n * i + k,
                            o + k
                        ));
                    }
                    s.push_str(&format!("                jrk[{i}u] -= {e};\n"));
                }
                s.push_str("            }\n");
            }
            let at = shp[b];
            for j in 0..n {
                let sum = |x: &dyn Fn(usize) -> String| -> String {
                    let mut e = String::from("0.0");
                    for i in 0..n {
                        e.push_str(&format!(" + SHP[{}u] * {}", at + j * n + i, x(i)));
                    }
                    e
                };
                let k = o + j;
                s.push_str(&format!(
                    "            {{\n                let u = {};\n                let v = {};\n                let aa = ({}) + FF[{k}u] / SHP[{}u];\n                let je = {};\n                FL[fli(e, 0u, {k}u)] = u;\n                FL[fli(e, 1u, {k}u)] = v;\n                FL[fli(e, 2u, {k}u)] = aa - ag;\n                FL[fli(e, 3u, {k}u)] = aa;\n                FL[fli(e, 4u, {k}u)] = je;\n            }}\n",
                    sum(&|i| format!("(*z)[{}u]", o + i)),
                    sum(&|i| format!("(*z)[{}u]", nm + o + i)),
                    sum(&|i| format!("acc[{i}u]")),
                    at + n * n + j,
                    sum(&|i| format!("jrk[{i}u]")),
                ));
            }
            s.push_str("        }\n");
        }
        s.push_str("        default: {}\n    }\n}\n");
        // RowRun::track_buildings (row_loops.wgsl's), each building and storey written out.
        s.push_str("fn track_buildings(z0: ptr<function, ZA>, z1: ptr<function, ZA>, ag0: real, ag1: real, h: real) {\n    if (ENDS_VALID) {\n        copy_floor_ends();\n    } else {\n        set_floor_forces(true);\n");
        for b in 0..self.storeys.len() {
            s.push_str(&format!("        fill({b}u, 0u, z0, ag0);\n"));
        }
        s.push_str("    }\n    set_floor_forces(false);\n");
        for b in 0..self.storeys.len() {
            s.push_str(&format!("    var touched{b} = false;\n"));
        }
        for (l, &[a, _, _]) in self.levels.iter().enumerate() {
            s.push_str(&format!(
                "    if (LMODE[{l}u] != MODE_FREE) {{\n        touched{a} = true;\n        touched{} = true;\n    }}\n",
                a + 1
            ));
        }
        for b in 0..self.storeys.len() {
            s.push_str(&format!("    fill({b}u, 1u, z1, ag1);\n"));
        }
        let fl = |e: usize, q: usize, k: usize| format!("FL[{}u]", (5 * e + q) * nm + k);
        for (b, &n) in self.storeys.iter().enumerate() {
            let (o, top) = (offs[b], offs[b] + n - 1);
            s.push_str(&format!(
                "    {{\n        let free = !touched{b};\n        let sb = RS + S_BUILDINGS + BS_STRIDE * {b}u;\n        let cb = RC + C_BUILDINGS + BC_STRIDE * {b}u;\n        rstate[sb + BS_ROOF] = raise(free, rstate[sb + BS_ROOF], {}, {}, {}, {}, {}, {}, h);\n        var drift = rstate[sb + BS_DRIFT];\n        var accel = rstate[sb + BS_ACCEL];\n",
                fl(0, 0, top), fl(1, 0, top), fl(0, 1, top), fl(1, 1, top), fl(0, 2, top), fl(1, 2, top)
            ));
            for j in 0..n {
                let k = o + j;
                // Floor 0 is the ground: it moves with the frame.
                let rel = |e: usize, q: usize| {
                    if j == 0 {
                        format!("({} - 0.0)", fl(e, q, k))
                    } else {
                        format!("({} - {})", fl(e, q, k), fl(e, q, k - 1))
                    }
                };
                s.push_str(&format!(
                    "        {{\n            let inv_h = 1.0 / height_at({b}u, {j}u);\n            let y0 = {} * inv_h;\n            let y1 = {} * inv_h;\n            let d0 = {} * inv_h;\n            let d1 = {} * inv_h;\n            let a0 = {} * inv_h;\n            let a1 = {} * inv_h;\n            let p = raise(free, drift, y0, y1, d0, d1, a0, a1, h);\n            if (p > drift) {{\n                drift = p;\n                rcount[cb + BC_DRIFT_STOREY] = {}u;\n            }}\n",
                    rel(0, 0), rel(1, 0), rel(0, 1), rel(1, 1), rel(0, 2), rel(1, 2), j + 1
                ));
                if self.yielding[b] {
                    s.push_str(&format!("            if (NS > 0u) {{\n                raise_storey({b}u, {j}u, free, y0, y1, d0, d1, a0, a1, h);\n            }}\n"));
                }
                s.push_str(&format!(
                    "            var pa: real;\n            if (free) {{\n                pa = raise_cubic_peak(accel, {}, {}, {}, {}, h);\n            }} else {{\n                pa = max(max(accel, abs({})), abs({}));\n            }}\n            if (pa > accel) {{\n                accel = pa;\n                rcount[cb + BC_ACCEL_FLOOR] = {}u;\n            }}\n        }}\n",
                    fl(0, 3, k), fl(0, 4, k), fl(1, 3, k), fl(1, 4, k), fl(0, 3, k), fl(1, 3, k), j + 1
                ));
            }
            s.push_str("        rstate[sb + BS_DRIFT] = drift;\n        rstate[sb + BS_ACCEL] = accel;\n    }\n");
        }
        s.push_str("}\n");
        // Yielding storeys (yielding.wgsl): each one's drift or its rate (StoreyModel::drift),
        // and their plastic loads in the right-hand side (row::plastic_rhs).
        let ns = str_at.len();
        if ns > 0 {
            s.push_str("fn storey_drift(s: u32, z: ptr<function, ZA>, at: u32) -> real {\n    switch s {\n");
            for (st, &(b, c)) in str_at.iter().enumerate() {
                let mut e = String::from("0.0");
                for i in 0..self.storeys[b] {
                    e.push_str(&format!(" + STR[{}u] * (*z)[at + {}u]", c + i, offs[b] + i));
                }
                s.push_str(&format!("        case {st}u: {{ return {e}; }}\n"));
            }
            s.push_str("        default: { return 0.0; }\n    }\n}\n");
            s.push_str("fn plastic_rhs(z: ptr<function, ZA>, out: ptr<function, ZA>) {\n");
            for (st, &(b, c)) in str_at.iter().enumerate() {
                let ps = self.plastic_slot0() + st;
                s.push_str(&format!(
                    "    {{\n        (*out)[{ps}u] = 0.0;\n        (*out)[{}u] = 0.0;\n        let p = (*z)[{ps}u];\n        let k = st_k({st}u);\n        let kp = k * p;\n",
                    ps + ns
                ));
                for i in 0..self.storeys[b] {
                    s.push_str(&format!(
                        "        (*out)[{}u] += STR[{}u] * kp;\n",
                        nm + offs[b] + i,
                        c + i
                    ));
                }
                // The plastic drift's rate over the drift's (`storey_flow` with IMK storeys).
                let flow = if self.has_imk() {
                    format!("storey_flow({st}u)")
                } else {
                    format!("(1.0 - st_b({st}u))")
                };
                s.push_str(&format!(
                    "        if (SM[{st}u] != SM_ELASTIC) {{\n            let dp = {flow} * storey_drift({st}u, z, NM);\n            (*out)[{ps}u] = dp;\n            (*out)[{}u] = k * (storey_drift({st}u, z, 0u) - p) * dp;\n        }}\n    }}\n",
                    ps + ns
                ));
            }
            s.push_str("}\n");
        } else {
            // An elastic row's kernel enters neither (`NS > 0` guards every call).
            s.push_str("fn storey_drift(s: u32, z: ptr<function, ZA>, at: u32) -> real {\n    return 0.0;\n}\nfn plastic_rhs(z: ptr<function, ZA>, out: ptr<function, ZA>) {}\n");
        }
        s.push_str("fn rhs(ag: real, z: ptr<function, ZA>, out: ptr<function, ZA>) {\n");
        for i in 0..nm {
            s.push_str(&format!(
                "    (*out)[{i}u] = (*z)[{v}u];\n    (*out)[{v}u] = -TXW[{i}u] * (*z)[{v}u] - W2[{i}u] * (*z)[{i}u] - PART[{i}u] * ag;\n",
                v = nm + i
            ));
        }
        for &(b, c) in &cpe {
            let n = self.storeys[b];
            s.push_str(&format!("    if (coupled({b}u)) {{\n"));
            for i in 0..n {
                let e = coupled_term(b, c, i);
                s.push_str(&format!("        (*out)[{}u] -= {e};\n", nm + offs[b] + i));
            }
            s.push_str("    }\n");
        }
        s.push_str("    if (NS > 0u) {\n        plastic_rhs(z, out);\n    }\n");
        for (l, (&[a, _, _], &[ra, rb])) in self.levels.iter().zip(&rows).enumerate() {
            let w = 2 * nm + l;
            s.push_str(&format!(
                "    if (LMODE[{l}u] == MODE_FREE) {{\n        (*out)[{w}u] = 0.0;\n    }} else {{\n"
            ));
            s.push_str(&format!(
                "        let d = delta({l}u, z);\n        let r = ddelta({l}u, z);\n        use_level({l}u);\n        let f = contact_force(d, r, LV0[{l}u], LMODE[{l}u] == MODE_APPROACH);\n"
            ));
            for (row, b, sign) in [(ra, a, "-"), (rb, a + 1, "+")] {
                for i in 0..self.storeys[b] {
                    s.push_str(&format!(
                        "        (*out)[{}u] {sign}= SHP[{}u] * f;\n",
                        nm + offs[b] + i,
                        row + i
                    ));
                }
            }
            s.push_str(&format!("        (*out)[{w}u] = f * r;\n    }}\n"));
        }
        let nl = self.levels.len();
        s.push_str(&format!(
            "    (*out)[{}u] = 0.0;\n    (*out)[{}u] = 0.0;\n}}\n",
            2 * nm + nl,
            2 * nm + nl + 1
        ));
        s
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every loop in the shaders ends after a count, as building them without naga's loop
    /// bounding requires (context.rs): no `while`, every `for` has a step, every `loop` leaves
    /// once its budget is spent and spends it each pass; the per-shape code the host writes
    /// has no loop at all.
    #[test]
    fn every_loop_counts() {
        use crate::engine::gpu::shader::{
            AGGREGATE_WGSL, CONTACT_WGSL, FAST_WGSL, HERMITE_WGSL, IMK_WGSL, LANES_WGSL,
            ROW_LOOPS_WGSL, ROW_WGSL, TYPES_WGSL, YIELDING_WGSL,
        };
        let shape = RowShape::elastic(vec![3, 6], vec![[0, 0, 0], [0, 1, 1]]);
        let written = shape.wgsl_constants();
        let sources = [
            ("types", TYPES_WGSL),
            ("contact", CONTACT_WGSL),
            ("hermite", HERMITE_WGSL),
            ("fast", FAST_WGSL),
            ("row", ROW_WGSL),
            ("row_loops", ROW_LOOPS_WGSL),
            ("yielding", YIELDING_WGSL),
            ("imk", IMK_WGSL),
            ("lanes", LANES_WGSL),
            ("aggregate", AGGREGATE_WGSL),
            ("written out for 3 + 6 storeys", written.as_str()),
        ];
        let (mut fors, mut loops) = (0, 0);
        for (name, src) in sources {
            let code: Vec<&str> = src.lines().map(|l| l.split("//").next().unwrap()).collect();
            for (i, line) in code.iter().enumerate() {
                let at = format!("{name}.wgsl line {}: {line}", i + 1);
                assert!(!line.contains("while"), "{at}");
                if let Some(h) = line.find("for (") {
                    let header = line[h..].split(") {").next().unwrap();
                    let clauses: Vec<&str> = header.split(';').collect();
                    assert_eq!(clauses.len(), 3, "{at}");
                    assert!(!clauses[2].trim().is_empty(), "{at}");
                    fors += 1;
                }
                if line.contains("loop {") {
                    let body = code[i..(i + 12).min(code.len())].join("\n");
                    assert!(body.contains("budget == 0u"), "{at}");
                    assert!(body.contains("budget = budget - 1u"), "{at}");
                    loops += 1;
                }
            }
            if name.starts_with("written") {
                assert!(!src.contains("for (") && !src.contains("loop {"));
            }
        }
        assert!(fors > 20 && loops == 2, "{fors} for, {loops} loop");
    }
}
