#!/usr/bin/env bash
# Regenerates docs/figures: one PNG (plotters) and one PDF (the pgfplots code compiled with
# pdflatex on a 14 cm x 11 cm page) of each figure kind of `moreau figure`. Needs pdflatex and
# pgfplots (Debian: texlive-latex-base texlive-pictures). The bam-xl330-* PNGs come from
# `moreau diagnose` (docs/guide/diagnose.md) and are left alone.
set -euo pipefail
cd "$(dirname "$0")/.."
cargo build --release --quiet -p moreau
bin=target/release/moreau
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
$bin figure psi examples/worked-example.toml --out "$tmp" >/dev/null 2>&1
$bin figure tube examples/worked-example.toml --out "$tmp" >/dev/null
$bin figure trajectory examples/worked-example.toml --out "$tmp" >/dev/null
$bin figure sweep examples/sweeps/amplitude --out "$tmp" >/dev/null
for stem in fig-psi1 fig-loop trajectory-yz sweep-theta-theta_best-measured_rate; do
    cp "$tmp/$stem.png" docs/figures/
    cat > "$tmp/doc-$stem.tex" <<TEX
\documentclass{article}
\usepackage[paperwidth=14cm,paperheight=11cm,margin=0.4cm]{geometry}
\usepackage{pgfplots}
\pgfplotsset{compat=1.11}
\pagestyle{empty}
\begin{document}
\centering
\input{$stem.tex}
\end{document}
TEX
    (cd "$tmp" && pdflatex -interaction=nonstopmode -halt-on-error "doc-$stem.tex" >/dev/null)
    cp "$tmp/doc-$stem.pdf" "docs/figures/$stem.pdf"
done
echo "docs/figures regenerated"
