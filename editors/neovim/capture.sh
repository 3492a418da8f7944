#!/usr/bin/env bash
# Makes docs/neovim-session.txt: Neovim in a tmux terminal, set up as docs/editors.md says,
# on grammars/wall.clay with a typo; the screen is captured once the diagnostic shows and again
# with the hover of `brick` open (K). Needs nvim, tmux and a built clayc
# (`cargo build --bin clayc`; CARGO_TARGET_DIR is honoured).
set -euo pipefail
cd "$(dirname "$0")/../.."
repo=$PWD
bin="${CARGO_TARGET_DIR:-$repo/target}/debug"
work=$(mktemp -d)
trap 'tmux kill-session -t clay-capture 2>/dev/null || true; rm -rf "$work"' EXIT
# The setup of docs/editors.md, plus K for hover (a default mapping only from Neovim 0.10).
awk '/^### Neovim/{n=1} n&&/^```lua$/{p=1;next} p&&/^```$/{exit} p' docs/editors.md > "$work/init.lua"
echo "vim.keymap.set('n', 'K', vim.lsp.buf.hover)" >> "$work/init.lua"
sed 's/site west: joint/site west: jiont/' grammars/wall.clay > "$work/wall.clay"
# The lines of the typo and of the chain whose `brick` is hovered, in the wall.clay of today.
typo_line=$(grep -n 'site west: jiont' "$work/wall.clay" | cut -d: -f1)
chain_line=$(grep -n 'chain brick' "$work/wall.clay" | cut -d: -f1)
cd "$work"
tmux new-session -d -s clay-capture -x 100 -y 32 \
    "env PATH=$bin:$PATH HOME=$work XDG_STATE_HOME=$work/state XDG_CACHE_HOME=$work/cache \
     CLAY_FOLLOW_DIR=$work/no-follow TERM=xterm-256color nvim -n -i NONE -u init.lua wall.clay"
sleep 3
tmux send-keys -t clay-capture ":$typo_line" Enter
sleep 1
tmux capture-pane -p -t clay-capture > diagnostic.txt
tmux send-keys -t clay-capture ":$chain_line" Enter '018l'
sleep 0.5
tmux send-keys -t clay-capture K
sleep 2
tmux capture-pane -p -t clay-capture > hover.txt
{
    echo "Neovim $(nvim --version | head -1 | cut -d' ' -f2) with \`clayc lsp\`, set up as docs/editors.md says, on"
    echo "grammars/wall.clay with a typo (\`jiont\`), in a 100 x 32 terminal captured with tmux"
    echo "(\`editors/neovim/capture.sh\` makes this file). The E in the sign column and the text after"
    echo "line $typo_line are the server's diagnostic E011; then the cursor on \`brick\` of line $chain_line and K."
    echo
    echo "== the diagnostic (cursor on line $typo_line)"
    echo
    cat diagnostic.txt
    echo
    echo "== the hover on \`chain brick\` (line $chain_line, K)"
    echo
    cat hover.txt
} > "$repo/docs/neovim-session.txt"
echo "wrote docs/neovim-session.txt"
