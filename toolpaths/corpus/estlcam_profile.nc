(Estlcam 11 style: G00/G01 with 4 decimals, F and S beside the first plunge, G04 P dwell)
(Project untitled)
(Created with Estlcam Version 11 Build 11.245)
(Machining time about 00:00:30 hours)

G21
G90
G94
F1000
S18000
M03
G00 Z5.0000
G00 X10.0000 Y10.0000

(No. 1: Part 1)
G00 Z0.5000
G01 Z-1.0000 F300 S18000
G01 X30.0000 F1000
G01 Y30.0000
G02 X20.0000 Y40.0000 I-10.0000 J0.0000
G01 X10.0000
G01 Y10.0000
G00 Z5.0000
G04 P0.5
G00 X0.0000 Y0.0000
M05
M30
