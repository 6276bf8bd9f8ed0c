//! Files in and out of the page: a download made from text (a Blob and a
//! temporary link) and the text of a file the user picked.

use wasm_bindgen::{JsCast, JsValue};

/// Offers `text` as a file named `name` to download.
pub fn download(name: &str, mime: &str, text: &str) -> Result<(), String> {
    offer(name, mime, &JsValue::from_str(text))
}

/// Offers `bytes` as a file named `name` to download.
pub fn download_bytes(name: &str, bytes: &[u8]) -> Result<(), String> {
    offer(
        name,
        "application/octet-stream",
        &js_sys::Uint8Array::from(bytes),
    )
}

fn offer(name: &str, mime: &str, part: &JsValue) -> Result<(), String> {
    let err = |e: JsValue| format!("the browser refused the download: {e:?}");
    let parts = js_sys::Array::of1(part);
    let opts = web_sys::BlobPropertyBag::new();
    opts.set_type(mime);
    let blob =
        web_sys::Blob::new_with_buffer_source_sequence_and_options(&parts, &opts).map_err(err)?;
    let url = web_sys::Url::create_object_url_with_blob(&blob).map_err(err)?;
    let document = web_sys::window()
        .and_then(|w| w.document())
        .ok_or("no document")?;
    let a: web_sys::HtmlAnchorElement = document
        .create_element("a")
        .map_err(err)?
        .dyn_into()
        .map_err(|_| "not an anchor".to_string())?;
    a.set_href(&url);
    a.set_download(name);
    a.click();
    web_sys::Url::revoke_object_url(&url).map_err(err)?;
    Ok(())
}

/// The first file chosen in a file input, with its name.
pub fn chosen_file(ev: &web_sys::Event) -> Option<web_sys::File> {
    let input: web_sys::HtmlInputElement = ev.target()?.dyn_into().ok()?;
    let file = input.files()?.get(0);
    // Let the same file be picked again later.
    input.set_value("");
    file
}

/// The text of a file: refused in words when larger than
/// [`plm_core::file::FILE_MAX`] (16 MiB, before it is read), or when it
/// is not UTF-8 text ([`plm_core::file::text`]); a UTF-8 byte order mark
/// is skipped. Read as bytes rather than with `File.text()`, which would
/// turn bytes that are not UTF-8 into U+FFFD without a word.
pub async fn read_text(file: &web_sys::File) -> Result<String, String> {
    let bytes = read_bytes(file).await?;
    plm_core::file::text(&bytes).map(str::to_string)
}

/// The bytes of a file; refused in words, before it is read, when larger
/// than [`plm_core::file::FILE_MAX`] (16 MiB).
pub async fn read_bytes(file: &web_sys::File) -> Result<Vec<u8>, String> {
    plm_core::file::check_size(file.size() as u64)?;
    let buffer = wasm_bindgen_futures::JsFuture::from(file.array_buffer())
        .await
        .map_err(|e| format!("the file could not be read: {e:?}"))?;
    Ok(js_sys::Uint8Array::new(&buffer).to_vec())
}
