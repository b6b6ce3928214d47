//! A folder's files as a zip: entries stored (KTX2 and PNG hold their own compression),
//! dated 1980-01-01 (the zip crate's date without a clock), so the same files make the
//! same zip.

use std::io::Write;

/// `files` (by name) inside the folder `folder`, zipped.
pub fn folder(folder: &str, files: &[(String, Vec<u8>)]) -> zip::result::ZipResult<Vec<u8>> {
    let mut zip = zip::ZipWriter::new(std::io::Cursor::new(Vec::new()));
    let options = zip::write::SimpleFileOptions::default().compression_method(zip::CompressionMethod::Stored);
    for (name, bytes) in files {
        zip.start_file(format!("{folder}/{name}"), options)?;
        zip.write_all(bytes)?;
    }
    Ok(zip.finish()?.into_inner())
}
