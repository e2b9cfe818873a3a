// A tabulated phase function: piecewise linear in the cosine between its
// rows, sampled by inverting its CDF, whose every segment is a quadratic.
// Mirrors crates/kernel/src/phase/table.rs (`segment_of`, `eval_cos`,
// `sample_cos`; the host's rows, `TabulatedPhase::rows`, flattened by
// flat.rs into `phase_table`: cosines, values, CDF). The CDF is read in
// f32 here (f64 on the CPU): a sample's density is the value's to f32's
// precision.

// Whether the medium's phase function is a table (flat.rs, `phase_lobes`).
fn is_table_phase() -> bool {
    return params.phase_b.w > 0.0;
}

// The segment [i, i + 1] holding `x` among the table's `base`-th column
// (0 cosines, 2 the CDF): the last row at or below `x`, at most the
// second last (`partition_point`, by bisection).
fn table_segment(x: f32, base: u32) -> u32 {
    let n = params.counts.z;
    var lo = 0u;
    var hi = n;
    loop {
        if lo >= hi {
            break;
        }
        iterations += 1u;
        let mid = (lo + hi) / 2u;
        if phase_table[base * n + mid] <= x {
            lo = mid + 1u;
        } else {
            hi = mid;
        }
    }
    return min(max(lo, 1u) - 1u, n - 2u);
}

// The table's value at cosine `mu` (`eval_cos`).
fn table_eval(mu_in: f32) -> f32 {
    let n = params.counts.z;
    let mu = clamp(mu_in, -1.0, 1.0);
    let i = table_segment(mu, 0u);
    let m0 = phase_table[i];
    let m1 = phase_table[i + 1u];
    let v0 = phase_table[n + i];
    let v1 = phase_table[n + i + 1u];
    let t = clamp((mu - m0) / (m1 - m0), 0.0, 1.0);
    return v0 + t * (v1 - v0);
}

// A cosine drawn from the table for uniform `u` (`sample_cos`): the
// segment by the CDF, then the root of its quadratic.
fn table_sample_cos(u: f32) -> f32 {
    let n = params.counts.z;
    let i = table_segment(u, 2u);
    let m0 = phase_table[i];
    let m1 = phase_table[i + 1u];
    let h = m1 - m0;
    let mu_density = params.phase_b.x;
    let q0 = mu_density * phase_table[n + i];
    let q1 = mu_density * phase_table[n + i + 1u];
    let r = max(u - phase_table[2u * n + i], 0.0);
    let denom = q0 + sqrt(max(q0 * q0 + 2.0 * (q1 - q0) * r / h, 0.0));
    let x = select(0.0, 2.0 * r / denom, denom > 0.0);
    return clamp(m0 + x, m0, m1);
}
