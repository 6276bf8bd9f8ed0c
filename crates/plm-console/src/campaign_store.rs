//! A firmware update campaign kept in the browser's storage, so that a
//! reload, a closed tab or a pulled cable loses nothing: the image once,
//! and the engine's progress ([`plm_core::app::update::Update::save`])
//! after every change. Both are forgotten when the campaign is over.

use crate::storage::{load, store};
use crate::street::StreetSession;
use plm_core::hex;

const IMAGE: &str = "plm-console.update.image";
const PROGRESS: &str = "plm-console.update.progress";
/// Hex digits of a saved progress up to the end of its header.
const HEADER_HEX: usize = 2 * 21;

/// Saves `s`'s campaign as it is now (called when it changed).
pub fn save(s: &StreetSession) {
    let Some(c) = s.campaign() else {
        return;
    };
    if c.update().is_done() {
        discard();
        return;
    }
    let progress = hex::encode(&c.update().save());
    // The image is written once per campaign: the progress starts with the
    // campaign's header (its size and CRC-32), 21 bytes in.
    let same = |p: &str| p.get(..HEADER_HEX) == progress.get(..HEADER_HEX);
    if !load(PROGRESS).is_some_and(|p| same(&p)) {
        store(IMAGE, Some(&hex::encode(c.update().image())));
    }
    store(PROGRESS, Some(&progress));
}

/// Whether a campaign is kept (cheap: the image is not read).
pub fn has_saved() -> bool {
    load(PROGRESS).is_some()
}

/// The campaign saved, if any: its image and its progress.
pub fn saved() -> Option<(Vec<u8>, Vec<u8>)> {
    let image = hex::parse(&load(IMAGE)?).ok()?;
    let progress = hex::parse(&load(PROGRESS)?).ok()?;
    Some((image, progress))
}

/// Forgets the saved campaign.
pub fn discard() {
    store(PROGRESS, None);
    store(IMAGE, None);
}

/// The campaign kept, in words (`release 1.8 to 12 lamp(s), 6000-byte
/// image`), or why it cannot be read.
pub fn describe() -> String {
    let Some((image, progress)) = saved() else {
        return "the update kept cannot be read".into();
    };
    match plm_core::app::update::Update::resume(image, &progress, 0) {
        Ok(u) => format!(
            "{} to {} lamp(s), {}-byte image",
            plm_core::app::rfu::release_words(u.header().release()),
            u.boards().count(),
            u.header().size
        ),
        Err(e) => format!("the update kept cannot be resumed: {e}"),
    }
}
