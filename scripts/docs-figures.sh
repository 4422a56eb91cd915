#!/usr/bin/env bash
# Regenerates docs/figures: one PNG (plotters) and one PDF (the pgfplots code compiled with
# pdflatex on a 14 cm x 11 cm page) of each figure kind of `moreau figure`. Needs pdflatex and
# pgfplots (Debian: texlive-latex-base texlive-pictures). The bam-xl330-* PNGs are `moreau
# diagnose` figures of the shipped BAM servo logs (docs/guide/diagnose.md), regenerated too.
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
for log in sin_sin sin_time_square; do
    $bin diagnose --model examples/real/bam-xl330-kp100.toml --data "data/bam-servo/xl330-kp100-$log.csv" \
        --out "$tmp/bam-$log" >/dev/null
    cp "$tmp/bam-$log/fit.png" "docs/figures/bam-xl330-kp100-$log-fit.png"
done
cp "$tmp/bam-sin_time_square/zoom-1.png" docs/figures/bam-xl330-kp100-sin_time_square-zoom-1.png
echo "docs/figures regenerated"
