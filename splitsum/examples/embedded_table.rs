//! Writes the BRDF table the library embeds (`splitsum::table`): the defaults' table,
//! computed afresh on the CPU. `bash scripts/dev.sh table` runs it; `tests/lut.rs` checks
//! that the committed file equals a fresh computation bit for bit.

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let path = std::env::args().nth(1).ok_or("usage: embedded_table PATH")?;
    let texels = splitsum::table::compute(splitsum::table::TableKey::EMBEDDED)?;
    std::fs::write(&path, splitsum::table::encode(&texels))?;
    println!("{path}: {} texels", texels.len());
    Ok(())
}
