# Command-line tests (see expect.sh). Arguments may use @TMP@ for a scratch dir.
crowdrecon_cli_test(help ok "shape" --help)
