/*
 * cli_import.h — the `import` command of the spinmodal CLI (cli_import.c),
 * called from cli.c's main().
 */
#ifndef SPINMODAL_CLI_IMPORT_H
#define SPINMODAL_CLI_IMPORT_H

/**
 * Run `spinmodal import ...`: argv[1] is "import".  Returns the exit code:
 * 0 imported, 1 I/O or memory failure, 2 the file is refused, 64 usage.
 */
int cli_import_main(int argc, char **argv);

#endif /* SPINMODAL_CLI_IMPORT_H */
