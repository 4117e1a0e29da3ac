//! How a message names an input the user gave: a flag of the `sagcal`
//! command or a keyword argument of the Python package ([`FrontEnd`]).

/// The front end that called a job: how a message names an input the user gave.
///
/// The jobs check their settings and word their refusals in the library; the
/// command line and the Python package only say which of them is asking, and
/// the message names the flag (`--encoder-sigma-m`) or the keyword argument
/// (`encoder_sigma_m`) the user wrote.
///
/// ```
/// use sagcal::error::FrontEnd;
/// assert_eq!(FrontEnd::Cli.option("encoder_sigma_m"), "--encoder-sigma-m");
/// assert_eq!(FrontEnd::Python.option("encoder_sigma_m"), "encoder_sigma_m");
/// assert_eq!(FrontEnd::Cli.switch("accept_inconsistent"), "--accept-inconsistent");
/// assert_eq!(FrontEnd::Python.switch("accept_inconsistent"), "accept_inconsistent=True");
/// ```
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum FrontEnd {
    /// The `sagcal` command: options are flags, `--encoder-sigma-m`.
    Cli,
    /// The Python package: options are keyword arguments, `encoder_sigma_m`.
    Python,
}

impl FrontEnd {
    /// The option whose Python keyword is `keyword` (snake case), as this
    /// front end spells it: `--encoder-sigma-m` or `encoder_sigma_m`.
    pub fn option(self, keyword: &str) -> String {
        match self {
            FrontEnd::Cli => format!("--{}", keyword.replace('_', "-")),
            FrontEnd::Python => keyword.to_string(),
        }
    }

    /// The on/off option `keyword`, turned on: `--accept-inconsistent` or
    /// `accept_inconsistent=True`.
    pub fn switch(self, keyword: &str) -> String {
        match self {
            FrontEnd::Cli => self.option(keyword),
            FrontEnd::Python => format!("{keyword}=True"),
        }
    }
}
