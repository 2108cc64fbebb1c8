"""One module per algorithm: its parameter spec and its run(), from which the QGIS toolbox
and the command line are both made."""
