//! The console's entry point: mounts the Leptos app on the page.

fn main() {
    leptos::mount::mount_to_body(plm_console::app::App);
}
