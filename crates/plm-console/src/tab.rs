//! The console's tabs: their names and the URL fragments that open them.

/// The views, in the order of the tabs.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Tab {
    /// The street of lamps (the page opens on it).
    Street,
    /// Remote firmware update of the street's boards.
    Update,
    /// Traffic inspector.
    Traffic,
    /// MIB configuration.
    Modem,
    /// Data requests and indications.
    Data,
    /// Ping, status, reset, counters.
    Diagnostics,
    /// An ST7570's S-FSK network.
    Network,
    /// The simulated world.
    Simulator,
}

impl Tab {
    /// Every tab.
    pub const ALL: [Tab; 8] = [
        Tab::Street,
        Tab::Update,
        Tab::Traffic,
        Tab::Modem,
        Tab::Data,
        Tab::Diagnostics,
        Tab::Network,
        Tab::Simulator,
    ];

    /// The tab's name.
    pub fn label(self) -> &'static str {
        match self {
            Tab::Street => "Street",
            Tab::Update => "Firmware update",
            Tab::Traffic => "Traffic",
            Tab::Modem => "Modem",
            Tab::Data => "Data",
            Tab::Diagnostics => "Diagnostics",
            Tab::Network => "Network",
            Tab::Simulator => "Simulator",
        }
    }

    /// The URL fragment that opens it (`#modem`).
    pub fn slug(self) -> &'static str {
        match self {
            Tab::Street => "street",
            Tab::Update => "update",
            Tab::Traffic => "traffic",
            Tab::Modem => "modem",
            Tab::Data => "data",
            Tab::Diagnostics => "diagnostics",
            Tab::Network => "network",
            Tab::Simulator => "simulator",
        }
    }

    pub(crate) fn from_hash(hash: &str) -> Tab {
        let h = hash.trim_start_matches('#');
        Tab::ALL
            .into_iter()
            .find(|t| t.slug() == h)
            .unwrap_or(Tab::Street)
    }
}
