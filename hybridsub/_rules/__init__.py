"""The scheme's rules (OpenSubdiv's Sdc): weights and limit masks as functions of
neighbourhood numbers. No mesh."""
