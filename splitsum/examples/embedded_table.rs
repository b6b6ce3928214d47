//! Writes the tables the library embeds (`splitsum::table`): the defaults' BRDF table and
//! the sheen tables, computed afresh on the CPU. `bash scripts/dev.sh table` runs it;
//! `tests/lut.rs` and `tests/sheen.rs` check that the committed files equal a fresh
//! computation bit for bit.

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut args = std::env::args().skip(1);
    let (Some(brdf), Some(sheen)) = (args.next(), args.next()) else {
        return Err("usage: embedded_table BRDF_PATH SHEEN_PATH".into());
    };
    let texels = splitsum::table::compute(splitsum::table::TableKey::EMBEDDED)?;
    std::fs::write(&brdf, splitsum::table::encode(&texels))?;
    println!("{brdf}: {} texels", texels.len());
    let texels = splitsum::table::compute_sheen();
    std::fs::write(&sheen, splitsum::table::encode(&texels))?;
    println!("{sheen}: {} texels", texels.len());
    Ok(())
}
