// Works offline once visited (docs/console.md, "Offline and install"): registers the
// service worker. A file rather than an inline script, so that the page's
// Content-Security-Policy allows no inline script but Trunk's loader
// (docs/console.md, "Content-Security-Policy"). A browser without service
// workers (or a page not in a secure context) just goes without; a
// failure is a warning, never an error: the console works either way.
if ('serviceWorker' in navigator) {
  addEventListener('load', () => {
    navigator.serviceWorker
      .register('./sw.js', { scope: './' })
      .catch((e) => console.warn('PLM Console: no offline support:', e));
  });
}
