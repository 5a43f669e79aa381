//! Derives for odc (work in progress).
use proc_macro::TokenStream;

/// Placeholder.
#[proc_macro_derive(Pdo, attributes(pdo))]
pub fn derive_pdo(_input: TokenStream) -> TokenStream {
    TokenStream::new()
}

/// Placeholder.
#[proc_macro_derive(PdoValue, attributes(pdo))]
pub fn derive_pdo_value(_input: TokenStream) -> TokenStream {
    TokenStream::new()
}
