//! `cirrus convert IN [--grid NAME] [--precision f32|f16|u8] -o OUT.cbrk`.

use super::CliResult;
use cirrus_bricks::{convert_file, write_cbrk, BrickError, Precision};
use cirrus_scene::grids::choose_grid;
use cirrus_vdb::VolumeFile;
use std::path::PathBuf;
use std::time::Instant;

#[derive(clap::Args)]
pub struct ConvertArgs {
    /// A .vdb or .nvdb file.
    pub input: PathBuf,
    /// The float grid to convert (default: "density", else the first float grid).
    #[arg(long)]
    pub grid: Option<String>,
    /// Voxel precision of the stored bricks.
    #[arg(long, default_value = "f32", value_parser = ["f32", "f16", "u8"])]
    pub precision: String,
    /// The .cbrk file to write.
    #[arg(short, long)]
    pub output: PathBuf,
}

pub fn run(args: &ConvertArgs) -> CliResult {
    let precision = Precision::from_name(&args.precision).expect("clap checked the name");
    if !cirrus_scene::has_extension(&args.output, "cbrk") {
        return Err(format!(
            "{}: convert writes bricks (.cbrk); name the output OUT.cbrk",
            args.output.display()
        )
        .into());
    }
    let file = VolumeFile::open(&args.input)?;
    let index = choose_grid(&file, args.grid.as_deref())?;
    // Streamed: a .vdb grid goes into bricks without the reader's tree.
    let start = Instant::now();
    let volume = convert_file(&file, index, precision).map_err(|e| match e {
        BrickError::Vdb(e) => e.to_string(),
        e => format!("{}: {e}", args.input.display()),
    })?;
    let convert_s = start.elapsed().as_secs_f64();
    let start = Instant::now();
    write_cbrk(&volume, &args.output)?;
    let write_s = start.elapsed().as_secs_f64();
    let i = &volume.info;
    eprintln!(
        "{}: grid {:?}, {} active voxels -> {} bricks stored, {} constant, {} empty ({} precision, max error {}); read and converted {:.3} s ({:.1} M active voxels/s), written {:.3} s, {} bytes",
        args.output.display(),
        i.grid_name,
        i.active_voxels,
        i.bricks_stored,
        i.bricks_constant,
        i.bricks_empty,
        precision.name(),
        match i.max_error {
            0.0 => "0, exact".to_string(),
            e => format!("{e:.3e}"),
        },
        convert_s,
        i.active_voxels as f64 / convert_s.max(1e-9) / 1e6,
        write_s,
        volume.total_bytes()
    );
    if i.sanitized_voxels > 0 {
        eprintln!(
            "warning: {} voxels were NaN, infinite or negative and are stored as 0",
            i.sanitized_voxels
        );
    }
    Ok(())
}
