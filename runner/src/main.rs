//! `runner`: bake, display and report split-sum image-based lighting.

fn main() {
    quiet_device_select();
    runner::log_warnings();
    if let Err(e) = runner::cli::run(std::env::args_os()) {
        match e.downcast_ref::<clap::Error>() {
            // Help and version exit 0, usage errors 2 (`cli::USAGE_EXIT`).
            Some(clap_error) => clap_error.exit(),
            None => {
                eprintln!("error: {e:#}");
                std::process::exit(runner::cli::exit_code(&e));
            }
        }
    }
}

/// Mesa's Vulkan device-selection layer (`VK_LAYER_MESA_device_select`, loaded implicitly
/// with Mesa's drivers) connects to the Wayland display while the adapters are listed, to
/// put the one driving the display first; without `XDG_RUNTIME_DIR` libwayland then prints
/// "error: XDG_RUNTIME_DIR is invalid or not set in the environment." twice on every GPU
/// run, successful ones included. With no runtime folder there is no Wayland display to
/// consult, and splitsum picks its adapter itself, so the layer is turned off through its
/// own switch (`NODEVICE_SELECT=1`, its manifest's `disable_environment`) unless the user
/// set that variable.
fn quiet_device_select() {
    let runtime_dir = std::env::var_os("XDG_RUNTIME_DIR").filter(|d| std::path::Path::new(d).is_dir());
    if runtime_dir.is_none() && std::env::var_os("NODEVICE_SELECT").is_none() {
        // SAFETY: the first statement of main, before any thread exists.
        unsafe { std::env::set_var("NODEVICE_SELECT", "1") };
    }
}
