//! The root component: the stores, the wake that runs the sessions
//! ([`crate::wake`]), the connection bar and the views.

use crate::profile::Profile;
use crate::stores::{provide_console, use_console};
use crate::tab::Tab;
use crate::views::connection_bar::ConnectionBar;
use crate::views::data::DataView;
use crate::views::diagnostics::DiagnosticsView;
use crate::views::modem::ModemView;
use crate::views::network::NetworkView;
use crate::views::sfsk_data::SfskDataView;
use crate::views::simulator::SimulatorView;
use crate::views::street::StreetView;
use crate::views::traffic::TrafficView;
use crate::views::update::UpdateView;
use crate::views::widgets::signal;
use leptos::prelude::*;

/// A parameter of the page's address (`?profile=st7580`).
fn query(name: &str) -> Option<String> {
    let search = web_sys::window()?.location().search().ok()?;
    let params = web_sys::UrlSearchParams::new_with_str(&search).ok()?;
    params.get(name)
}

fn current_hash() -> String {
    web_sys::window()
        .and_then(|w| w.location().hash().ok())
        .unwrap_or_default()
}

/// The whole console.
#[component]
pub fn App() -> impl IntoView {
    let console = provide_console();
    // A simulated street is there at once, so a newcomer sees lamps on any
    // machine; `?profile=st7580` opens on the simulated modem.
    // Else the profile chosen last time (the chip is remembered).
    let chosen = query("profile").or_else(|| crate::storage::load(crate::stores::PROFILE_KEY));
    if let Some(p) = chosen.and_then(|k| Profile::from_key(&k)) {
        console.profile.set(p);
    }
    // `?lamps=500`: a longer simulated street (demos, `cargo xtask bench`).
    if let Some(n) = query("lamps").and_then(|n| n.parse::<usize>().ok()) {
        console.sim.lamps.set(n.clamp(1, crate::stores::MAX_LAMPS));
    }
    // `?speed=N`: the simulated street N times as fast (demos, tests).
    if let Some(n) = query("speed").and_then(|n| n.parse::<u32>().ok()) {
        console.sim.speed.set(n.clamp(1, 20));
    }
    // `?street=uniform`: every simulated lamp alike (tests counting exact
    // values); the demo's lamps differ as a real street's.
    if query("street").as_deref() == Some("uniform") {
        console.sim.uniform.set(true);
    }
    console.connect_simulated();
    crate::bench_hook::install(console);
    crate::wake::install(move || console.tick());
    crate::wake::soon();
    // The tab shown, by its slug: a String signal, a type the page has
    // (a signal type of its own brings its own code, docs/console.md "Size").
    let tab = signal(Tab::from_hash(&current_hash()).slug().to_string());
    let on_hash = window_event_listener(leptos::ev::hashchange, move |_| {
        tab.set(Tab::from_hash(&current_hash()).slug().to_string());
    });
    on_cleanup(move || on_hash.remove());
    // Leaving the page mid-update asks first (the campaign is kept and
    // can be resumed, but the boards wait meanwhile).
    let street = console.street;
    let on_leave = window_event_listener(leptos::ev::beforeunload, move |ev| {
        if street.read(|s| s.campaign().is_some_and(|c| !c.update().is_done())) {
            ev.prevent_default();
            ev.set_return_value("a firmware update is under way");
        }
    });
    on_cleanup(move || on_leave.remove());
    // The lamps' readings are written as the page is left: a reload
    // keeps them.
    let on_hide = window_event_listener(leptos::ev::pagehide, move |_| street.keep_history(true));
    on_cleanup(move || on_hide.remove());

    view! {
        <div class="app">
            <div class="chrome">
            <header class="top">
                <h1 class="brand">"PLM Console"</h1>
                <ConnectionBar/>
            </header>
            <nav class="tabs" role="tablist">
                {Tab::ALL
                    .into_iter()
                    .map(|t| {
                        view! {
                            <a
                                role="tab"
                                class="tab"
                                href=format!("#{}", t.slug())
                                id=format!("tab-{}", t.slug())
                                class:active=move || tab.get() == t.slug()
                                aria-selected=move || (tab.get() == t.slug()).to_string()
                            >
                                {t.label()}
                            </a>
                        }
                    })
                    .map(IntoAny::into_any).collect_view()}
            </nav>
            </div>
            <main>
                <Panel tab=tab which=Tab::Street>
                    <StreetView/>
                </Panel>
                <Panel tab=tab which=Tab::Update>
                    <UpdateView tab=tab/>
                </Panel>
                <Panel tab=tab which=Tab::Traffic>
                    <TrafficView tab=tab/>
                </Panel>
                <Panel tab=tab which=Tab::Modem>
                    <ModemView/>
                </Panel>
                <Panel tab=tab which=Tab::Data>
                    <St7580Only what="data services (PHY, DL, SS)" st7570=|| view! { <SfskDataView/> }.into_any()>
                        <DataView tab=tab/>
                    </St7580Only>
                </Panel>
                <Panel tab=tab which=Tab::Diagnostics>
                    <St7580Only what="diagnostics (ping, reset, counters, firmware)">
                        <DiagnosticsView/>
                    </St7580Only>
                </Panel>
                <Panel tab=tab which=Tab::Network>
                    <NetworkView/>
                </Panel>
                <Panel tab=tab which=Tab::Simulator>
                    <SimulatorView tab=tab/>
                </Panel>
            </main>
            <LinkProblem/>
        </div>
    }
}

/// One view, kept mounted (its form state survives a change of tab) and
/// hidden unless its tab is chosen.
#[component]
fn Panel(tab: RwSignal<String>, which: Tab, children: Children) -> impl IntoView {
    view! {
        <section
            class="panel"
            role="tabpanel"
            id=format!("view-{}", which.slug())
            hidden=move || tab.get() != which.slug()
        >
            {children()}
        </section>
    }
}

/// A view of what only the ST7580 has: shown unless the ST7570 profile
/// is chosen, when the ST7570's counterpart (`st7570`) shows instead, or
/// where to find it. A memo of the choice rather than `<Show>` (one more
/// generic component in the page, docs/console.md "Size"); like
/// `<Show>`, the view is only made anew when the choice changes, so its
/// form state survives a change between the ST7580 profiles.
#[component]
fn St7580Only(
    what: &'static str,
    #[prop(optional)] st7570: Option<fn() -> AnyView>,
    children: ChildrenFn,
) -> impl IntoView {
    let console = use_console();
    let chosen = Memo::new(move |_| console.profile.get() == Profile::St7570);
    move || {
        if !chosen.get() {
            children().into_any()
        } else if let Some(view) = st7570 {
            view()
        } else {
            view! {
                <article class="card">
                    <p class="muted">
                        {format!("These ST7580 {what} do not apply to the ST7570. Its MIB is in the Modem view, its network in Network and its frames, decoded in its access layer, in Traffic.")}
                    </p>
                </article>
            }
            .into_any()
        }
    }
}

/// What to do about the link (advice), else its last problem, in words,
/// until dismissed.
#[component]
fn LinkProblem() -> impl IntoView {
    let console = use_console();
    let (problem, advice) = (console.conn.last_problem, console.conn.advice);
    let text = move || advice.get().or_else(|| problem.get());
    view! {
        {move || text().map(|t| view! {
            <div class="toast" role="status" id="link-problem">
                <span>{t}</span>
                {crate::views::widgets::button("", "Dismiss", "", move || {
                    advice.set(None);
                    problem.set(None);
                })}
            </div>
        }.into_any())}
    }
}
