//! Generator of recordings with concealed effects.
