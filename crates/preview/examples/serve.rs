//! `cargo run --release --example serve -- FILE [--port P] [--bind ADDR]
//! [--res WxH] [--max-spp N]`: the preview server without the `cirrus`
//! binary (what `cirrus preview` runs).

use cirrus_preview::{start, Config};

fn main() {
    if let Err(e) = run() {
        eprintln!("serve: {e}");
        std::process::exit(1);
    }
}

fn run() -> Result<(), Box<dyn std::error::Error>> {
    let mut args = std::env::args().skip(1);
    let mut config = Config::new(args.next().ok_or("usage: serve FILE [--port P] ...")?);
    while let Some(flag) = args.next() {
        let value = args.next().ok_or_else(|| format!("{flag} needs a value"))?;
        match flag.as_str() {
            "--port" => config.port = value.parse()?,
            "--bind" => config.bind = value.parse()?,
            "--res" => config.res = Some(cirrus_scene::parse::resolution(&value)?),
            "--max-spp" => config.max_spp = value.parse()?,
            _ => return Err(format!("unknown flag {flag}").into()),
        }
    }
    let preview = start(config)?;
    println!("cirrus preview: {}", preview.url());
    preview.wait();
    Ok(())
}
