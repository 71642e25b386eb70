"""Acceptance of the discrepancy stage on force- and voltage-driven campaigns of a jointed beam (issue 30).

Each case: a virtual-lab campaign (`jointcal.synth.generate`: exact-Iwan time simulation of the
jointed beam of `tests/_support/rigs.py` on its open-loop shaker, the DAQ chain, 2% noise) of three levels
at two sweep rates (eta 0.5 and 2 at the middle level), one hidden effect at a given strength;
measured (`measure_run`), calibrated (GA on eq. 3.9, the modal model kind), then
`jointcal.discrepancy.diagnose` with the modal library (time-domain revalidation included).
The rig has no second mode but in the neighbour_mode case, where one sits at 150 Hz (0.25 lbf at the
driving point: the neighbour a lab's accelerometer reads). Prints per case: the
effect named, confidence, E before and after, the stage's time.

    python tests/benchmarks/accept_discrepancy_modal.py [--ref force,voltage] [--seeds 1,2,3]
        [--only NAME] [--out FILE]

Acceptance (issue 30): each effect named with confidence high in >= 5 of 6 campaigns and E falling
by >= 70%; 'none' 6 of 6; contact_spring 'unexplained'; elastic_softening + cubic_stiffening both
named in >= 2 of 3 seeds. Status 2026-11-27 (the last section): every naming line met; the stage under 2 minutes
in every campaign measured (at most 101 s, the voltage pair). History: measured 2026-11-26, seed 1 only, on a loaded 2-core machine
(hidden effect, rig: named, confidence, time-domain E before -> after, the fast model's floor E):

    none                                 force    seed 1: none                                 medium E   0.59 ->  1.74 (+195%)  floor 4.16, stage 28 s
    none                                 voltage  seed 1: unexplained                          low    E   1.20 ->  1.04 ( -13%)  floor 0.16, stage 35 s
    elastic_softening                    force    seed 1: unexplained                          low    E   8.87 ->  4.08 ( -54%)  floor 6.21, stage 110 s
    elastic_softening                    voltage  seed 1: unexplained                          low    E   5.30 ->  0.97 ( -82%)  floor 0.17, stage 74 s
    cubic_stiffening                     force    seed 1: cubic_stiffening                     medium E  10.53 ->  0.63 ( -94%)  floor 1.67, stage 90 s
    cubic_stiffening                     voltage  seed 1: unexplained                          low    E   5.30 ->  1.50 ( -72%)  floor 0.17, stage 92 s
    neighbour_mode                       force    seed 1: neighbour_mode                       medium E 110.88 ->  6.31 ( -94%)  floor 3.85, stage 109 s
    neighbour_mode                       voltage  seed 1: neighbour_mode                       medium E  91.42 ->  3.39 ( -96%)  floor 0.10, stage 110 s
    joint_settling                       force    seed 1: unexplained                          low    E   5.40 ->  3.51 ( -35%)  floor 4.06, stage 64 s
    joint_settling                       voltage  seed 1: unexplained                          low    E   3.72 ->  1.45 ( -61%)  floor 0.16, stage 39 s
    channel_delay                        force    seed 1: unexplained                          low    E  50.00 -> 45.16 ( -10%)  floor 2.60, stage 143 s
    channel_delay                        voltage  seed 1: unexplained                          low    E   3.52 ->  2.91 ( -17%)  floor 0.16, stage 63 s
    elastic_softening+cubic_stiffening   force    seed 1: cubic_stiffening                     medium E   9.38 ->  0.94 ( -90%)  floor 1.86, stage 40 s
    elastic_softening+cubic_stiffening   voltage  seed 1: unexplained                          low    E   6.03 ->  1.68 ( -72%)  floor 0.19, stage 42 s
    contact_spring                       force    seed 1: unexplained                          low    E  22.18 -> 11.29 ( -49%)  floor 1.04, stage 42 s
    contact_spring                       voltage  seed 1: unexplained                          low    E  14.91 ->  4.59 ( -69%)  floor 0.22, stage 60 s

The force rig's floor (E 3-8 on its eta-2 runs) was the open-loop force's dip at resonance: five-fold within a few
cycles, its phase turning with it, which a drive of frame magnitudes alone did not follow. With the drive's complex
envelope (merge of 2026-11-26, `models.swept`: |A| e^{i psi}) four force rows, rerun (seed 1, loaded machine;
the other rows not rerun yet):

    none                                 force    seed 1: none                                 high   E   0.59 ->  0.58 (  -2%)  floor 0.25, stage 131 s
    cubic_stiffening                     force    seed 1: cubic_stiffening                     high   E  10.53 ->  0.57 ( -95%)  floor 0.24, stage 172 s
    elastic_softening                    force    seed 1: elastic_softening                    high   E   8.87 ->  0.70 ( -92%)  floor 0.35, stage 626 s (niced behind the suite)
    joint_settling                       force    seed 1: unexplained                          low    E   5.40 ->  3.16 ( -41%)  floor 0.24, stage 137 s

The voltage rows, measured 2026-11-26, seed 1 only, voltage rig, on a heavily loaded 2-core machine (load
average 9-18 from other jobs: the stage times are several times an idle machine's). Before: main at c31223e (the
complex drive), this benchmark end to end (killed after joint_settling for time):

    none                                 voltage  seed 1: unexplained                          low    E   1.20 ->  1.04 ( -13%)  floor 0.14, stage 86 s
    elastic_softening                    voltage  seed 1: unexplained                          low    E   5.30 ->  0.97 ( -82%)  floor 0.15, stage 139 s
    cubic_stiffening                     voltage  seed 1: unexplained                          low    E   5.30 ->  1.50 ( -72%)  floor 0.16, stage 176 s
    neighbour_mode                       voltage  seed 1: neighbour_mode                       medium E  91.42 ->  3.39 ( -96%)  floor 0.09, stage 666 s
    joint_settling                       voltage  seed 1: unexplained                          low    E   3.72 ->  1.44 ( -61%)  floor 0.15, stage 401 s

Two causes, both of the voltage rig. (1) The validation's scale pooled the two sweep rates of a level as repeats
(a set voltage gives both the same level): near resonance their transients differ by 0.7-0.9 dB and 6.5-9 deg,
13-20x the runs' own noise, so every near-resonance effect was divided away (`validate.error.repeat_scatter` now
groups by sweep rate too). (2) The drive's modal constant A(w): the read-out's slope, fitted over the passage
through resonance with a ridge, is a tenth of the coil's phase slope; over the discrepancy band this left a phase
misfit linear in w in every candidate (baseline E 1.60 hiding nothing; `discrepancy.drive.refine_slope` refits the
slope with the baseline, again with the best-scoring candidate, and with the named model). After (the kept
campaigns and calibrations of the run above, measured, validated and diagnosed again with this code; E before is
the validation's E on the new scale; elastic_softening's loss ratio 0.306 [0.291, 0.319], truth 0.30; the refit
slope A' w_c / A_c -0.006-0.090i with the none, elastic and cubic models, the read-out's -0.001-0.009i;
joint_settling's baseline finds +0.078-0.095i, moved by the drift it misses):

    none                                 voltage  seed 1: none                                 high   E   1.42 ->  0.66 ( -54%)  floor 0.18, stage 161 s
    elastic_softening                    voltage  seed 1: elastic_softening                    high   E   5.96 ->  0.69 ( -88%)  floor 0.20, stage 150 s
    cubic_stiffening                     voltage  seed 1: cubic_stiffening                     high   E   9.12 ->  0.65 ( -93%)  floor 0.18, stage 222 s
    joint_settling                       voltage  seed 1: unexplained                          low    E   4.32 ->  2.24 ( -48%)  floor 0.18, stage 133 s

Two more voltage rows with this code, end to end (new campaigns, seed 1, same machine):

    channel_delay                        voltage  seed 1: none                                 high   E   4.21 ->  0.86 ( -79%)  floor 0.18, stage 167 s
    contact_spring                       voltage  seed 1: unexplained                          low    E  16.61 ->  7.75 ( -53%)  floor 0.22, stage 154 s

channel_delay is wrong: on a voltage drive the read-out's complex modal constant takes the delay's phase at
resonance (-w_c tau) and the refit slope the rest (A' w_c / A_c -0.005-0.330i against the coil's -0.09i), so the
baseline with the refit drive reproduces the runs (held-out 1.23) and the time check does not contradict it. A
coil turning the phase that far would also tilt |A(w)| (real part about -0.1, here -0.005): a fingerprint of a delay
on a voltage rig, not used yet. neighbour_mode and the elastic+cubic pair (voltage) not rerun. The force rows none,
elastic_softening and cubic_stiffening rerun on this branch (seed 1, same machine; started before its last two
commits, which touch only voltage campaigns: a force run's level is its measured force, no two alike) are unchanged: none high
0.59 -> 0.58 floor 0.25 (267 s); elastic_softening high 8.87 -> 0.70 floor 0.35 (365 s); cubic_stiffening high
10.53 -> 0.57 floor 0.24 (148 s).

joint_settling was generated per spec, one spec per sweep rate: the hidden drift restarted at each rate's first run
(synth's sequence 1-3 twice), while the campaign here numbers the runs 1-6; the library's settling, monotonic in
the sequence, could not follow that on either rig. Each rate's spec now continues the sequence (synth's
``first_sequence``, 2026-11-26): the drift runs on over the six runs as a lab's would. Rerun then (seeds 1-3, the
machine shared with another job):

    joint_settling                       force    seed 1: joint_settling                       high   E   9.84 ->  0.57 ( -94%) floor 0.24 stage 68 s
    joint_settling                       force    seed 2: joint_settling                       high   E   9.86 ->  0.58 ( -94%) floor 0.25 stage 63 s
    joint_settling                       force    seed 3: joint_settling                       high   E   9.83 ->  0.59 ( -94%) floor 0.27 stage 68 s
    joint_settling                       voltage  seed 1: joint_settling+neighbour_mode        high   E   7.12 ->  0.68 ( -91%) floor 0.17 stage 95 s
    joint_settling                       voltage  seed 2: joint_settling+neighbour_mode        high   E   7.10 ->  0.66 ( -91%) floor 0.20 stage 103 s
    joint_settling                       voltage  seed 3: joint_settling+neighbour_mode        high   E   7.12 ->  0.70 ( -90%) floor 0.17 stage 58 s

Named alone on the force rig; on the voltage rig with a spurious neighbouring mode: settling alone scores 2.90 held
out (E 1.54-1.58 on all runs, where the noise gives about 1), the pair 1.78-1.87, under the rule's 0.7 x the best
single. Not yet understood; a lead: the drive's slope (`discrepancy.drive.refine_slope`) is first refit with the
baseline, which misses the drift, and the neighbour's residual term takes up what the slope then holds wrong.

The neighbouring mode, 2026-11-26 (the machine shared with other runs). Before (main at be2e617), seeds 1-3:

    neighbour_mode                       force    seed 1: neighbour_mode                       medium E 110.88 ->  5.83 ( -95%) floor 0.17 stage 76 s
    neighbour_mode                       force    seed 2: neighbour_mode                       medium E 114.42 ->  5.75 ( -95%) floor 0.18 stage 83 s
    neighbour_mode                       force    seed 3: cubic_stiffening+neighbour_mode      medium E 102.72 ->  5.19 ( -95%) floor 0.16 stage 115 s
    neighbour_mode                       voltage  seed 1: neighbour_mode                       medium E  43.48 ->  6.67 ( -85%) floor 0.08 stage 128 s
    neighbour_mode                       voltage  seed 2: neighbour_mode                       medium E  40.26 ->  6.67 ( -83%) floor 0.08 stage 120 s
    neighbour_mode                       voltage  seed 3: neighbour_mode                       medium E  41.85 ->  6.78 ( -84%) floor 0.08 stage 121 s

The hidden neighbour's modal constant is 4x the mode's (0.25 lbf against 1.0): the library's mode_ratio sat on
its bound of 3 (interval 2.997-3.000). On the voltage rig the baseline's slope refit also bent the drive to the
neighbour (A' w_c / A_c -6.6+1.3i; neighbour held-out 15.1). After (mode_ratio -10..10 from 1; a refit slope
past a coil's, |A' w_c / A_c| > 1, rejected), seed 1:

    neighbour_mode                       force    seed 1: neighbour_mode                       medium E 110.88 ->  1.72 ( -98%) floor 0.17 stage 57 s
    neighbour_mode                       voltage  seed 1: neighbour_mode                       medium E  43.48 ->  3.15 ( -93%) floor 0.08 stage 56 s
    none                                 force    seed 1: none                                 high   E   0.59 ->  0.58 (  -2%) floor 0.25 stage 49 s
    none                                 voltage  seed 1: none                                 high   E   1.42 ->  0.66 ( -53%) floor 0.18 stage 34 s
    elastic_softening                    voltage  seed 1: elastic_softening                    high   E   5.96 ->  0.69 ( -88%) floor 0.20 stage 104 s
    elastic_softening+cubic_stiffening   voltage  seed 1: cubic_stiffening                     high   E   6.98 ->  0.92 ( -87%) floor 0.23 stage 76 s
    cubic_stiffening                     voltage  seed 1: cubic_stiffening                     high   E   9.12 ->  0.65 ( -93%) floor 0.18 stage 51 s
    cubic_stiffening                     force    seed 1: cubic_stiffening                     high   E  10.53 ->  0.57 ( -95%) floor 0.24 stage 69 s

The neighbour's held-out scores (3.91 force, 3.38 voltage; 8.44 and 15.08 before) stay above the rule's 2 for
high: not yet understood. Seeds 2-3 of the neighbour (force, voltage) after, same day:

    neighbour_mode                       force    seed 2: neighbour_mode                       medium E 114.42 ->  1.65 ( -99%) floor 0.18 stage 93 s
    neighbour_mode                       force    seed 3: neighbour_mode                       medium E 102.72 ->  1.61 ( -98%) floor 0.16 stage 145 s
    neighbour_mode                       voltage  seed 2: neighbour_mode                       medium E  40.26 ->  2.98 ( -93%) floor 0.08 stage 126 s
    neighbour_mode                       voltage  seed 3: neighbour_mode                       medium E  41.85 ->  3.10 ( -93%) floor 0.08 stage 176 s

Why the neighbour stayed medium (branch 'neighbour', 2026-11-26). Force: no extrapolation; its fit on all runs was
already 3.73 (seed 1), per run 1.64-1.71 at eta 0.5 and 4.96-5.02 at eta 2, every fold alike. Each eta-2 run's 5.0 was
its last frame, whose window reaches past the sweep's stop (the force at 37% of full; the open-loop force's full-drive
fraction, 0.05, kept it): the fast model 2.8 dB and 24 deg off the time simulation of the same fitted model there (40
and 45 sigma). The fits now leave out every frame whose window reaches past the sweep's span (`data.within_sweep`,
placed in time), and the neighbour's fit starts also from the best point of a grid over its frequency and ratio (from
its one start it slid to the bound once that frame was gone; and a refreshing fit had never tried the spread starts
`starts` asks for). Same campaigns, seeds 1-3 (machine loaded, load average 5-8: stage times several times idle's):

    neighbour_mode                       force    seed 1: neighbour_mode                       high   E 110.88 ->  1.71 ( -98%) floor 0.17 stage 79 s   held-out 1.58 (was 3.91)
    neighbour_mode                       force    seed 2: neighbour_mode                       high   E 114.42 ->  1.63 ( -99%) floor 0.18 stage 145 s  held-out 1.50
    neighbour_mode                       force    seed 3: neighbour_mode                       high   E 102.72 ->  1.59 ( -98%) floor 0.16 stage 146 s  held-out 1.45
    neighbour_mode                       voltage  seed 1: neighbour_mode                       medium E  43.48 ->  3.13 ( -93%) floor 0.08 stage 171 s  held-out 3.34 (was 3.38)
    none                                 force    seed 1: none                                 high   E   0.59 ->  0.57 (  -3%) floor 0.25 stage 74 s   baseline 0.85 (was 1.24)
    none                                 voltage  seed 1: none                                 high   E   1.42 ->  0.66 ( -53%) floor 0.18 stage 74 s   baseline 0.95
    cubic_stiffening                     force    seed 1: cubic_stiffening                     high   E  10.53 ->  0.56 ( -95%) floor 0.24 stage 108 s  held-out 0.87
    cubic_stiffening                     voltage  seed 1: cubic_stiffening                     high   E   9.12 ->  0.65 ( -93%) floor 0.18 stage 130 s
    elastic_softening                    force    seed 1: elastic_softening                    high   E   8.87 ->  0.65 ( -93%) floor 0.35 stage 128 s  held-out 1.38
    elastic_softening                    voltage  seed 1: elastic_softening                    high   E   5.96 ->  0.69 ( -88%) floor 0.20 stage 135 s  held-out 1.05
    joint_settling                       force    seed 1: joint_settling                       high   E   9.84 ->  0.57 ( -94%) floor 0.24 stage 64 s   held-out 1.14
    joint_settling                       voltage  seed 1: joint_settling+neighbour_mode        high   E   7.12 ->  0.67 ( -91%) floor 0.17 stage 81 s   (as before)
    elastic_softening+cubic_stiffening   voltage  seed 1: cubic_stiffening+elastic_softening   high   E   6.98 ->  0.69 ( -90%) floor 0.23 stage 104 s  pair 1.09 (was the cubic alone)
    channel_delay                        voltage  seed 1: none                                 high   E   4.21 ->  0.86 ( -80%) floor 0.18 stage 26 s   (as before: wrong)
    neighbour_mode                       voltage  seed 2: neighbour_mode                       medium E  40.26 ->  2.96 ( -93%) floor 0.08 stage 78 s   held-out 3.22 (main: medium, 2.98)

The pair on voltage, seeds 2-3, after (e0c182b, 18:37-18:47, the machine shared with one other job; scores of the
best candidates held out):

    elastic_softening+cubic_stiffening   voltage  seed 2: cubic_stiffening                     high   E   7.16 ->  0.94 ( -87%) stage 80 s   cubic 1.80, +delay 1.87, +neighbour 1.90, +elastic 1.92 (loss_ratio 0.55)
    elastic_softening+cubic_stiffening   voltage  seed 3: unexplained                          low    E   7.39 ->  3.15 ( -57%) stage 124 s  baseline 2.87, cubic+delay 1.84, cubic 2.07 (closes 43% < 60%), +elastic 2.09

So the pair is named both in 1 of 3 voltage seeds (seed 1): not met. In every seed the top level's fold carries the
score (3.0-3.5 for the cubic and every pair with it). Before the merge (bb788ef, seed 1): voltage cubic alone (the
pair 1.50 against the cubic's 1.89, the rule's margin 0.7 not met); force seed 1 the cubic alone at 1.48 <= NONE_E,
so no pair tried (k3 2.97e8 against the truth's 3.68e8 per unit modal mass: the cubic and the refit Iwan absorb the
softening). Force seeds 1-2 after the merge (18:42-18:47, the two side by side):

    elastic_softening+cubic_stiffening   force    seed 1: cubic_stiffening                     high   E   9.38 ->  0.87 ( -91%) stage 63 s   cubic 1.17 <= NONE_E: no pair tried; k3 2.93e8
    elastic_softening+cubic_stiffening   force    seed 2: cubic_stiffening                     high   E   9.37 ->  0.89 ( -91%) stage 62 s   cubic 1.11: no pair tried; k3 2.94e8

On the force rig the cubic with the refit Iwan predicts every held-out fold within the scatter (folds 0.81-1.45):
these campaigns (three levels, 2% noise, loss_ratio 0.3) do not ask for the second effect, and the cubic's k3 is
20% low (truth 3.68e8 per unit modal mass) where it absorbs the softening.

bench_discrepancy.py, the base rig, `--index 0,1,3,5,8,9,10,11`, main bb788ef against the branch b9ade76 side by
side: every decision, confidence, floor, baseline score and E the same in all 8; the cubic's recalibrated joint
nearer the truth (mean |log error| 0.58 -> 0.04). Not rerun: force channel_delay, contact_spring; seeds 2-3 but the
neighbour's and the voltage pair's.

What is left. Force: the read-out's modal constant A_c is 1.7% high with the neighbour (392.57 against 1/m = 386.09;
386.07 in the 'none' campaign): a uniform +1.7 sigma magnitude misfit, E on all runs 1.37-1.49 (seeds 1-3); with A_c = 386.09 the
neighbour's E is 0.78 and held-out 0.82 (seed 1). Voltage: the library's term cannot be the rig's neighbour. The
shaker loads the driving point u = x + y: the back-EMF and the armature act on the neighbour's motion too, so on a
voltage drive the neighbour is not a term added to the response. Fitted to the rig's exact linear FRF (69-128 Hz, joint
stuck), A(w) (T1 + N) is left at best E 5.1 over 0.07 dB / 0.5 deg (1.79 dB and 7.3 deg at the antiresonance,
111.7 Hz; f_n 136 Hz, ratio 2.0 against 150 Hz and 4); exact (E 0.00) on the force rig and without the second mode;
0.65 with Bl 100x smaller (no electrical damping), 2.28 with the armature 5000x lighter. The stage's fit: E 2.72 on
all runs, largest frames 110-112.4 Hz (up to 14 sigma), f_ratio 1.43, mode_ratio 2.26.
The matrix on main at 96f6c0b, 2026-11-26, 19:50-21:08 (one campaign at a time; the machine shared with another
benchmark, load average 2.3-6.8): contact_spring and channel_delay (force) in seeds 1-3, and seeds 2-3 of none,
cubic_stiffening, elastic_softening and the voltage pair (the pair through the CASES entry, `--only elastic_softening`
naming both it and the effect alone):

    contact_spring                       force    seed 1: unexplained                          low    E  22.18 -> 11.29 ( -49%) floor 0.50 (per run 0.1 0.1 0.0 1.1 0.3 0.5) stage 97 s
    contact_spring                       force    seed 2: unexplained                          low    E  22.18 -> 11.39 ( -49%) floor 0.50 (per run 0.0 0.1 0.0 1.1 0.3 0.5) stage 97 s
    contact_spring                       force    seed 3: unexplained                          low    E  22.31 -> 11.41 ( -49%) floor 0.52 (per run 0.1 0.1 0.0 1.1 0.4 0.5) stage 72 s
    contact_spring                       voltage  seed 1: unexplained                          low    E  16.61 ->  7.68 ( -54%) floor 0.22 (per run 0.0 0.0 0.0 0.4 0.2 0.3) stage 104 s
    contact_spring                       voltage  seed 2: unexplained                          low    E  16.48 ->  7.84 ( -52%) floor 0.23 (per run 0.0 0.0 0.0 0.4 0.2 0.2) stage 139 s
    contact_spring                       voltage  seed 3: unexplained                          low    E  16.46 ->  7.80 ( -53%) floor 0.22 (per run 0.0 0.0 0.0 0.4 0.2 0.2) stage 75 s
    channel_delay                        force    seed 1: neighbour_mode+channel_delay         medium E  50.00 ->  2.31 ( -95%) floor 0.16 (per run 0.0 0.0 0.0 0.2 0.2 0.2) stage 397 s
    channel_delay                        force    seed 2: unexplained                          low    E  50.00 -> 45.12 ( -10%) floor 0.16 (per run 0.0 0.0 0.0 0.3 0.2 0.2) stage 132 s
    channel_delay                        force    seed 3: unexplained                          low    E  50.17 -> 45.27 ( -10%) floor 0.18 (per run 0.0 0.0 0.0 0.3 0.2 0.2) stage 97 s
    none                                 force    seed 2: none                                 high   E   0.85 ->  0.58 ( -32%) floor 0.25 (per run 0.0 0.0 0.0 0.4 0.3 0.3) stage 31 s
    none                                 force    seed 3: none                                 high   E   0.61 ->  0.59 (  -5%) floor 0.26 (per run 0.0 0.0 0.0 0.4 0.3 0.3) stage 29 s
    none                                 voltage  seed 2: none                                 high   E   1.44 ->  0.67 ( -53%) floor 0.20 (per run 0.1 0.0 0.0 0.3 0.3 0.2) stage 25 s
    none                                 voltage  seed 3: none                                 high   E   1.44 ->  0.66 ( -54%) floor 0.18 (per run 0.1 0.1 0.0 0.3 0.3 0.2) stage 33 s
    cubic_stiffening                     force    seed 2: cubic_stiffening                     high   E  10.81 ->  0.57 ( -95%) floor 0.25 (per run 0.0 0.0 0.0 0.4 0.3 0.3) stage 83 s
    cubic_stiffening                     force    seed 3: cubic_stiffening                     high   E  10.79 ->  0.58 ( -95%) floor 0.25 (per run 0.0 0.0 0.0 0.4 0.3 0.3) stage 76 s
    cubic_stiffening                     voltage  seed 2: cubic_stiffening                     high   E   9.16 ->  0.63 ( -93%) floor 0.20 (per run 0.0 0.0 0.0 0.3 0.3 0.2) stage 80 s
    cubic_stiffening                     voltage  seed 3: cubic_stiffening                     high   E   9.05 ->  0.61 ( -93%) floor 0.18 (per run 0.0 0.0 0.0 0.3 0.2 0.2) stage 111 s
    elastic_softening                    force    seed 2: elastic_softening                    high   E   5.64 ->  0.69 ( -88%) floor 0.34 (per run 0.1 0.1 0.1 0.5 0.4 0.5) stage 91 s
    elastic_softening                    force    seed 3: elastic_softening                    high   E   9.06 ->  0.69 ( -92%) floor 0.36 (per run 0.1 0.1 0.1 0.6 0.4 0.4) stage 103 s
    elastic_softening                    voltage  seed 2: elastic_softening                    high   E   5.86 ->  0.69 ( -88%) floor 0.22 (per run 0.1 0.1 0.1 0.3 0.3 0.3) stage 99 s
    elastic_softening                    voltage  seed 3: elastic_softening                    high   E   5.92 ->  0.68 ( -89%) floor 0.19 (per run 0.1 0.1 0.1 0.3 0.3 0.3) stage 110 s
    elastic_softening+cubic_stiffening   voltage  seed 2: cubic_stiffening                     high   E   7.16 ->  0.94 ( -87%) floor 0.24 (per run 0.1 0.1 0.0 0.3 0.4 0.3) stage 129 s
    elastic_softening+cubic_stiffening   voltage  seed 3: unexplained                          low    E   7.39 ->  3.15 ( -57%) floor 0.21 (per run 0.0 0.1 0.1 0.3 0.3 0.3) stage 111 s

contact_spring 'unexplained' in 6 of 6; with the seed-1 rows of branch 'neighbour' above (not rerun on 96f6c0b),
'none' 6 of 6, and cubic_stiffening and elastic_softening high in 6 of 6 with E -88% to -95%.
channel_delay (force) named with confidence high in none of 3: seed 1 with a spurious neighbour, medium (the delay alone
held-out 33.3, the neighbour 33.3, the pair 2.31); seeds 2-3 unexplained (the delay alone 33.5, the neighbour's fit
stays at 45.0-45.2, the pair 31.5-31.6). The voltage pair as on e0c182b, line for line (seed 2 the cubic alone, seed 3
unexplained): in seed 3 the first scoring had the pair at held-out 1.35 against the cubic's 1.88 (the rule's 0.7 asks
1.32); after the drive's slope was refit with that pair (-0.016-0.095j -> -0.014-0.087j) the pair scored 2.09 (E on
all runs 1.00 -> 1.66) and the cubic 2.07. The pair named both in 1 of 3 voltage seeds (seed 1): not met.

A voltage drive's slope refit with the best single effect before forward selection (branch 'slope', 2026-11-26
22:10-23:25; the machine loaded by two other jobs, load average 6-10: stage times several times idle's). The
baseline misses the hidden effect, and the slope it refits is bent by that miss (joint_settling seed 1:
0.049-0.106j against the coil's -0.09i); forward selection judged pairs on that slope, and a neighbouring mode
took up the bend. Now the slope is refit with the best single and the singles scored again before pairs are
considered (a pair that then leads refits it once more), and every rescoring also starts each candidate from its
fit on the previous slope. joint_settling with the single's slope: -0.008-0.092j, E on all runs 1.47 -> 1.00,
held-out 2.75 -> 1.43, no pair needed. Seed 1 and the pair's seed 3 rediagnosed on the kept campaigns of the run
before (`--keep`), the rest end to end:

    joint_settling                       voltage  seed 1: joint_settling                       high   E   7.12 ->  0.71 ( -90%) floor 0.17 stage 366 s
    joint_settling                       voltage  seed 2: joint_settling                       high   E   7.10 ->  0.66 ( -91%) floor 0.20 stage 154 s
    joint_settling                       voltage  seed 3: joint_settling                       high   E   7.12 ->  0.67 ( -91%) floor 0.17 stage 122 s
    elastic_softening+cubic_stiffening   voltage  seed 1: cubic_stiffening+elastic_softening   high   E   6.98 ->  0.69 ( -90%) floor 0.23 stage 394 s
    elastic_softening+cubic_stiffening   voltage  seed 2: cubic_stiffening                     high   E   7.16 ->  0.95 ( -87%) floor 0.24 stage 285 s
    elastic_softening+cubic_stiffening   voltage  seed 3: cubic_stiffening                     high   E   7.39 ->  0.92 ( -88%) floor 0.21 stage 399 s
    contact_spring                       voltage  seed 1: unexplained                          low    E  16.38 ->  7.68 ( -53%) floor 0.21 stage 139 s

joint_settling is named alone, high, in 6 of 6 (force seeds 1-3 above; the force rig refits no slope, so its rows
stand). The pair's seed 3 was unexplained: after the slope moved, the cubic refit from the calibration alone landed
at E 1.77 on all runs (1.42 before); from its previous fit 1.07, held-out 1.71, and the pair 1.35 (the rule's 0.7
asks 1.20): the cubic alone, high. Seeds 1-2 end to end before the warm starts (seed 2's pair 1.98-2.08 against the
cubic's 1.85-1.99). The pair is named both in 1 of 3 voltage seeds: not met; the other two name the cubic, high.
channel_delay on the force rig (branch 'delay', 2026-11-26). The cause was the read-out, not the stage: the swept-mode
fit held a force's modal constant real (A = 1/m), and a response channel lagging the force by 14 deg at the mode
cannot be followed by a real A. The fit took the hysteretic share phi to 1, the damping 32-55% high (seed 2: 0.0162,
0.0177, 0.0198 against the harmonic balance's 0.0104, 0.0122, 0.0150 at the amplitudes reached), f_res +0.3% and |A|
25-38% above 1/m (481-534 against 386.1), misfit 0.05 (under modal.sweep_misfit 0.1: read silently). The calibration
took that damping, and the stage drove every candidate through that |A|: a magnitude misfit no joint and no delay can
follow, so the delay alone scored 33.5 held out and only the neighbour's residual term (taking up the |A| error) with
the delay closed it (pair 2.29-2.31, medium). Before (main at 5e5b6cd, seed 2 rerun): neighbour_mode+channel_delay
medium E 50.00 -> 2.34 (stage 767 s, loaded machine). Now a force's A takes a phase where it earns its place (the
information criterion and the misfit's sum of squares cut 1.5x, as the residual terms), and `drive_gain` drives a force
through |A| (1/m, real: the phase is the channels', left for the stage to find). The read-out of seed 2: damping 0.0104,
0.0121, 0.0147; |A| 384.9; A's phase -13.8 deg (-W_0 tau -14.2); misfit 0.005-0.007. With the read-out right, the
calibrated model misses only the delay: E before is 33 (was 50, the biased calibration's). After (seeds 1-3, the
machine shared with two other agents' jobs, load 7-9; baseline, delay and neighbour held-out scores; tau fitted by the
stage, truth 400 us):

    channel_delay                        force    seed 1: channel_delay                        high   E  32.94 ->  0.67 ( -98%) floor 0.25 (per run 0.1 0.0 0.0 0.4 0.3 0.3) stage 259 s   32.38 / 0.94 / 31.78, tau 400.1 us*
    channel_delay                        force    seed 2: channel_delay                        high   E  33.20 ->  0.66 ( -98%) floor 0.25 (per run 0.0 0.0 0.0 0.4 0.3 0.3) stage 256 s   32.40 / 0.87 / 31.79, tau 399.3 us [398.7, 400.0]
    channel_delay                        force    seed 3: channel_delay                        high   E  32.96 ->  0.66 ( -98%) floor 0.26 (per run 0.0 0.0 0.0 0.4 0.3 0.3) stage 258 s   32.31 / 0.88 / 31.72, tau 399.8 us*
    none                                 force    seed 1: none                                 high   E   0.59 ->  0.57 (  -3%) floor 0.25 (per run 0.1 0.0 0.0 0.4 0.3 0.3) stage 141 s
    cubic_stiffening                     force    seed 1: cubic_stiffening                     high   E  10.50 ->  0.56 ( -95%) floor 0.24 (per run 0.0 0.0 0.0 0.4 0.4 0.3) stage 305 s

(* the delay candidate's least-squares fit on the kept campaign, re-measured; seed 2's the stage's recalibration with
its 90% interval. The read-out's phases of A, seeds 1 and 3: -13.72 to -13.78 deg in all 12 runs, |A| 385.0.)
(none and cubic before: high 0.59 -> 0.58 and high 10.53 -> 0.57.) The cubic's two top-level runs (1.19 V) earn a
phase of their own, +0.50 and -0.01 deg (seed 1: the sum of squares cut 2.6x on run 3, phi 1 either way): the
single-mode averaged model's misfit at the top level, not a channel's lag; |A| 386.7 either way, E before 10.53 ->
10.50. A campaign-level test (a delay's phase the same -w tau in every run, a model's misfit growing with the level)
would tell them apart; not done. Voltage paths not touched (a voltage's A is complex and sloped as before).

After the merge, a regression and its fix (2026-11-26, main ea535fb). With a neighbouring mode above the mode, the
freed phase took leads of +1.1 to +1.6 deg growing with the level, |A| 397-404 (1/m 386): neighbour_mode force seed 1
fell to medium (E 111.20 -> 2.77, held-out 2.64). A channel's delay only lags, so A's phase is kept only where it is
a lag, judged on the read-out with the residual terms it keeps (`measure.sweepfit._lags`; one run's trial lag of
-0.8 deg became a +1.4 deg lead with them). End to end on ea535fb (load 4-5, the suite beside it):

    neighbour_mode                       force    seed 1: neighbour_mode                       high   E 110.88 ->  1.71 ( -98%) floor 0.17 stage 132 s
    channel_delay                        force    seed 2: channel_delay                        high   E  33.20 ->  0.66 ( -98%) floor 0.25 stage 126 s

A voltage drive's slope refit as a coil's (2026-11-27, main 0be4e07 and after; the machine shared with another
agent's jobs, load 5-8: stage times several times idle's). The free complex slope took a channel delay into the drive
(seed 1: -0.005-0.330i against the coil's -0.009-0.093i) and left the delay nothing to explain ('none'). The slope is
now a coil's, one constant x = w_c L / R (`drive.coil_slope`: its phase slope tied to its magnitude tilt); a delay's
slope is all phase. Refit with the baseline the coil took what it could (x 0.32, E on all runs 2.10), and on that drive
the delay scored about the baseline (2.21 against 2.51) and a neighbouring mode best (1.83); so each single that fits
better than the baseline is scored again on the coil refit with it, and the best there leads (delay 1.21 with x 0.101,
the neighbour 1.42). A voltage model's delay counts from w_c, where the read-out's A_c holds it. Seeds 1-3 of
channel_delay, none, joint_settling, the pair and contact_spring rediagnosed on their kept campaigns (`--keep`), the
rest end to end:

    channel_delay                        voltage  seed 1: channel_delay                        high   E   4.21 ->  0.90 ( -79%)  (was none)
    channel_delay                        voltage  seed 2: channel_delay                        high   E   4.28 ->  0.90 ( -79%)  (was none)
    channel_delay                        voltage  seed 3: channel_delay                        high   E   4.27 ->  0.90 ( -79%)  (was none)
    none                                 voltage  seed 1: none                                 high   E   1.42 ->  0.66 ( -53%)
    none                                 voltage  seed 2: none                                 high   E   1.44 ->  0.67 ( -53%)
    none                                 voltage  seed 3: none                                 high   E   1.44 ->  0.66 ( -54%)
    joint_settling                       voltage  seed 1: joint_settling                       high   E   7.12 ->  0.71 ( -90%)
    joint_settling                       voltage  seed 2: joint_settling                       high   E   7.10 ->  0.66 ( -91%)
    joint_settling                       voltage  seed 3: joint_settling                       high   E   7.12 ->  0.67 ( -91%)
    elastic_softening                    voltage  seed 1: elastic_softening                    high   E   5.96 ->  0.69 ( -88%)
    elastic_softening                    voltage  seed 2: elastic_softening                    high   E   5.86 ->  0.69 ( -88%)
    elastic_softening                    voltage  seed 3: elastic_softening                    high   E   5.92 ->  0.68 ( -89%)
    cubic_stiffening                     voltage  seed 1: cubic_stiffening                     high   E   9.12 ->  0.65 ( -93%)
    cubic_stiffening                     voltage  seed 2: cubic_stiffening                     high   E   9.16 ->  0.63 ( -93%)
    cubic_stiffening                     voltage  seed 3: cubic_stiffening                     high   E   9.05 ->  0.61 ( -93%)
    elastic_softening+cubic_stiffening   voltage  seed 1: cubic_stiffening+elastic_softening   high   E   6.98 ->  0.69 ( -90%)
    elastic_softening+cubic_stiffening   voltage  seed 2: cubic_stiffening                     high   E   7.16 ->  0.95 ( -87%)
    elastic_softening+cubic_stiffening   voltage  seed 3: cubic_stiffening+elastic_softening   high   E   7.39 ->  0.74 ( -90%)  (was the cubic alone)
    neighbour_mode                       voltage  seed 1: neighbour_mode                       medium E  43.48 ->  3.15 ( -93%)
    contact_spring                       voltage  seed 1: unexplained                          low    E  16.38 ->  7.70 ( -53%)

channel_delay is named high in 6 of 6 (force seeds 1-3 above). The pair's seed 3: on the drive refit with the cubic
(-0.008-0.088j) the pair scored 1.26 held out against the cubic's 1.80, at the rule's margin (0.7 x 1.80 = 1.26):
both named, so the pair is named both in 2 of 3 seeds, the second at the margin. Rerun after the last change (the
coil left where a single leaves it, ef5b7ec): channel_delay seed 1 high 4.21 -> 0.90, the pair's seed 3 both
high 7.39 -> 0.74 (stage 204 s and 325 s). The real UNESP beam (its floor now 0.99, under the scatter: the coil is
refit, x 0.059): unexplained (low), E 9.36 -> 8.15 (8.6 before), verdict No unchanged. The neighbour on the voltage rig stays medium (the shaker couples the modes:
`neighbour_voltage_form.py`). Stage times under that load: 94-767 s (the pair's seeds 538-767 s; before the coil was
left unrefit where a single leaves it, 0.0-0.2% of x).

The neighbour on the voltage rig, 2026-11-27 (main 2f25372; the kept campaigns rediagnosed, seeds 2-3 of the
neighbour end to end; two campaigns at a time, load 2-4). The library's neighbour on voltage sweeps now sits in the
shaker's loop (`jointcal.models.Neighbour`, (N1)-(N2); `neighbour_voltage_form.py`: the rig's exact FRF to E 0.016
where the added term leaves 5.1), with the read-out's drive constant divided out (read_gain, read_phase: the one-mode
read-out is 32% high beside it) and the back-EMF a share of the mode's viscous damping (a free 2 zeta_e took 0.48 on
channel_delay's seed 1 and was named there in the delay's place: neighbour 1.21 held out, the delay 2.59):

    neighbour_mode                       voltage  seed 1: neighbour_mode                       high   E  43.48 ->  0.43 ( -99%) stage 121 s  (was medium, 3.15)
    neighbour_mode                       voltage  seed 2: neighbour_mode                       high   E  40.26 ->  0.39 ( -99%) stage 116 s  (was medium)
    neighbour_mode                       voltage  seed 3: neighbour_mode                       high   E  41.85 ->  0.44 ( -99%) stage 124 s  (was medium)
    neighbour_mode                       force    seed 1: neighbour_mode                       high   E 110.57 ->  1.71 ( -98%) stage 72 s
    none                                 voltage  seed 1: none                                 high   E   1.42 ->  0.66 ( -53%) stage 49 s
    none                                 voltage  seed 2: none                                 high   E   1.44 ->  0.67 ( -53%) stage 46 s
    none                                 voltage  seed 3: none                                 high   E   1.44 ->  0.66 ( -54%) stage 44 s
    joint_settling                       voltage  seed 1: joint_settling                       high   E   7.12 ->  0.71 ( -90%) stage 93 s
    joint_settling                       voltage  seed 2: joint_settling                       high   E   7.10 ->  0.66 ( -91%) stage 85 s
    joint_settling                       voltage  seed 3: joint_settling                       high   E   7.12 ->  0.67 ( -91%) stage 85 s
    channel_delay                        voltage  seed 1: channel_delay                        high   E   4.21 ->  0.90 ( -79%) stage 81 s
    channel_delay                        voltage  seed 2: channel_delay                        high   E   4.28 ->  0.90 ( -79%) stage 62 s
    channel_delay                        voltage  seed 3: channel_delay                        high   E   4.27 ->  0.90 ( -79%) stage 79 s
    elastic_softening                    voltage  seed 1: elastic_softening                    high   E   5.96 ->  0.69 ( -88%) stage 143 s
    cubic_stiffening                     voltage  seed 1: cubic_stiffening                     high   E   9.12 ->  0.65 ( -93%) stage 90 s
    elastic_softening                    voltage  seed 2: elastic_softening                    high   E   5.86 ->  0.69 ( -88%) stage 166 s
    elastic_softening                    voltage  seed 3: elastic_softening                    high   E   5.92 ->  0.68 ( -89%) stage 148 s
    cubic_stiffening                     voltage  seed 2: cubic_stiffening                     high   E   9.16 ->  0.63 ( -93%) stage 94 s
    cubic_stiffening                     voltage  seed 3: cubic_stiffening                     high   E   9.05 ->  0.61 ( -93%) stage 105 s
    elastic_softening+cubic_stiffening   voltage  seed 1: cubic_stiffening+elastic_softening   high   E   6.98 ->  0.69 ( -90%) stage 384 s
    elastic_softening+cubic_stiffening   voltage  seed 2: cubic_stiffening                     high   E   7.16 ->  0.94 ( -87%) stage 186 s
    elastic_softening+cubic_stiffening   voltage  seed 3: cubic_stiffening+elastic_softening   high   E   7.39 ->  0.74 ( -90%) stage 243 s
    contact_spring                       voltage  seed 1: unexplained                          low    E  16.38 ->  7.70 ( -53%) stage 122 s

The recalibrated neighbour of seed 1: f_ratio 1.54, mode_ratio 4.29, armature 0.047 of the loaded mass, back-EMF
2 zeta_e 0.0087, read-out 1.315 x the mode's constant; the linear fit to the rig's exact FRF gives 1.54, 4.32, 0.048,
0.0090 and 1.320. The neighbour is named high in 6 of 6 (force seeds 1-3 above). The real UNESP beam and the dwell
campaign: unchanged (unexplained, E 9.36 -> 8.15 and 78.2 -> 11.8). Stage times: the looped neighbour's fits cost
17-20 s a scoring on the voltage rig (2-5 s before), scored in every pass: the pair's stage is the slowest.
Alone on the machine afterwards (load 1.5-2, its own two workers): the neighbour's seed 1 89 s (singles 27, the
recalibration 22, the time-domain revalidation 33), the pair's seed 3 193 s (recalibration 66, singles 45, pairs 34,
revalidation 28, drive 19): over 2 minutes.

2026-11-27, later (d1a2d4b): the stage on its pool. The candidates of each scoring pass are fitted side by side on
the stage's process pool (the longest first), as are the singles' drive refits and the valley refits, and each batch
of the recalibration's GA and chain is split in halves, the second on the pool (always in halves, pool or not, so the
numbers do not depend on it); the envelope kernel releases the GIL and continues all runs in one call. Every
diagnosis below is the same as before, to the last digit but the timings. The same kept campaigns, rediagnosed one
at a time with the workflow's one BLAS thread per process (the earlier times above ran the harness with two BLAS
threads in each worker, which the workflow's stage jobs never do):

    campaign (voltage unless said)   before   now     steps now (s)
    pair (elastic + cubic) seed 3    193 s    122, 129, 136, 123 s   recalibration 54-57 (the chain 47), singles 22-30,
                                                                     pairs 22-27, drive 12-14, revalidation 7-8
    neighbour_mode seed 1             89 s    53 s     recalibration 27, singles 12, revalidation 8
    neighbour_mode (force) seed 1      -      50 s     recalibration 24, pairs 9, singles 8, revalidation 9
    none seed 1                        -      31 s     recalibration 21, singles 5
    contact_spring seed 1          122 s (load)  59 s  pairs 20, singles 14, recalibration 13

Every campaign but the voltage pair is well under 2 minutes; the pair stays at 2 minutes (122-136 s over four
runs). Its floor is the chain: 800 steps x 32 walkers of the fast model, about 3 ms of CPU per parameter set, in
two processes on two cores. A shorter chain would change the intervals; it was not shortened.

2026-11-27, later still (main 26330d9): the fast model's kernel. Each root of the amplitude balance took 4.6
evaluations of K_z, one of them the bracket's nearer end evaluated a second time; the root now keeps each end's
residual, slope and K_z (bit-identical). The non-Masing joint's share of its elastic backbone took M =
int cos^(chi+3) t dt by 16 Gauss-Legendre powers at every evaluation; in microslip it is Wallis' integral, two
lgamma (residuals move by <= 1.4e-6, on residuals of order 1-30). 16 parameter sets of the pair's objective,
two runs each on the quiet machine: 34-43 -> 14-22 ms. The 23 kept campaigns (`--keep` of the runs above)
rediagnosed one at a time, the machine otherwise idle: every name, confidence and E before and after as before (to 4 decimals). Stage times, before
(mostly d1a2d4b or earlier, some under load) -> now:

    pair (elastic + cubic) voltage    seeds 1-3: 384 (load), 186, 123 -> 101, 74, 87 s
    elastic_softening voltage         seeds 1-3: 143, 166, 148 -> 46, 44, 44 s
    cubic_stiffening voltage          seeds 1-3: 90, 94, 105 -> 47, 48, 43 s
    neighbour_mode voltage            seeds 1-3: 53, 116, 124 -> 48, 51, 45 s
    joint_settling voltage            seeds 1-3: 93, 85, 85 -> 56, 58, 48 s
    channel_delay voltage             seeds 1-3: 84, 62, 79 -> 33, 34, 37 s
    none voltage                      seeds 1-3: 31, 46, 44 -> 27, 27, 26 s
    contact_spring voltage            seed 1: 59 -> 49 s
    neighbour_mode force              seed 1: 50 -> 40 s

And the force rig end to end, seed 1 (this script, `--ref force --seeds 1`, alone on the machine):

    none                                 force    seed 1: none                                 high   E   0.59 ->  0.57 (  -3%) floor 0.25 stage 28 s
    elastic_softening                    force    seed 1: elastic_softening                    high   E   8.87 ->  0.65 ( -93%) floor 0.34 stage 37 s
    cubic_stiffening                     force    seed 1: cubic_stiffening                     high   E  10.53 ->  0.56 ( -95%) floor 0.24 stage 49 s
    neighbour_mode                       force    seed 1: neighbour_mode                       high   E 110.88 ->  1.71 ( -98%) floor 0.17 stage 39 s
    joint_settling                       force    seed 1: joint_settling                       high   E   9.84 ->  0.57 ( -94%) floor 0.24 stage 50 s
    channel_delay                        force    seed 1: channel_delay                        high   E  32.94 ->  0.67 ( -98%) floor 0.25 stage 37 s
    elastic_softening+cubic_stiffening   force    seed 1: cubic_stiffening                     high   E   9.38 ->  0.87 ( -91%) floor 0.32 stage 41 s
    contact_spring                       force    seed 1: unexplained                          low    E  22.18 -> 11.29 ( -49%) floor 0.50 stage 41 s

The real UNESP beam (`pytest -m acceptance tests/workflow/test_real_records.py`): unexplained (low), E 9.36 ->
8.15 as before, the stage 36 s (43-44 s before).

The force rig's seeds 2-3 end to end on 821cddf (`--ref force --seeds 2,3`, alone on the machine, 09:47-10:08):
every row recorded before is the same but cubic_stiffening seed 2's E before (10.58; 10.81 in the matrix of
2026-11-26, before the read-out changes since); the stage at most 48 s:

    none                                 force    seed 2: none                                 high   E   0.85 ->  0.58 ( -32%) floor 0.25 stage 31 s
    none                                 force    seed 3: none                                 high   E   0.61 ->  0.59 (  -5%) floor 0.26 stage 29 s
    elastic_softening                    force    seed 2: elastic_softening                    high   E   5.64 ->  0.69 ( -88%) floor 0.34 stage 40 s
    elastic_softening                    force    seed 3: elastic_softening                    high   E   9.06 ->  0.69 ( -92%) floor 0.36 stage 47 s
    cubic_stiffening                     force    seed 2: cubic_stiffening                     high   E  10.58 ->  0.57 ( -95%) floor 0.24 stage 48 s
    cubic_stiffening                     force    seed 3: cubic_stiffening                     high   E  10.79 ->  0.58 ( -95%) floor 0.25 stage 44 s
    neighbour_mode                       force    seed 2: neighbour_mode                       high   E 114.42 ->  1.63 ( -99%) floor 0.18 stage 47 s
    neighbour_mode                       force    seed 3: neighbour_mode                       high   E 102.72 ->  1.59 ( -98%) floor 0.16 stage 41 s
    joint_settling                       force    seed 2: joint_settling                       high   E   9.86 ->  0.58 ( -94%) floor 0.25 stage 45 s
    joint_settling                       force    seed 3: joint_settling                       high   E   9.83 ->  0.59 ( -94%) floor 0.27 stage 44 s
    channel_delay                        force    seed 2: channel_delay                        high   E  33.20 ->  0.66 ( -98%) floor 0.25 stage 37 s
    channel_delay                        force    seed 3: channel_delay                        high   E  32.96 ->  0.66 ( -98%) floor 0.26 stage 39 s
    elastic_softening+cubic_stiffening   force    seed 2: cubic_stiffening                     high   E   9.37 ->  0.89 ( -91%) floor 0.33 stage 40 s
    elastic_softening+cubic_stiffening   force    seed 3: cubic_stiffening                     high   E   9.93 ->  0.86 ( -91%) floor 0.36 stage 47 s
    contact_spring                       force    seed 2: unexplained                          low    E  22.18 -> 11.39 ( -49%) floor 0.50 stage 41 s
    contact_spring                       force    seed 3: unexplained                          low    E  22.31 -> 11.41 ( -49%) floor 0.52 stage 42 s

A seed none of the rows above used, both rigs end to end on 64c0d34 (`--ref force --seeds 4` and `--ref voltage
--seeds 4` side by side, 10:55-11:12, so each stage time is that of one core shared with the other run): every
effect named, confidence high, E down 79-99%; none named none; contact unexplained; the pair named both on the
voltage rig and the cubic alone on the force rig, as with seeds 1-3. The voltage pair's stage took 121 s beside
the other run:

    none                                 force    seed 4: none                                 high   E   0.58 ->  0.57 (  -1%) floor 0.25 stage 53 s
    elastic_softening                    force    seed 4: elastic_softening                    high   E   9.01 ->  0.65 ( -93%) floor 0.34 stage 71 s
    cubic_stiffening                     force    seed 4: cubic_stiffening                     high   E  10.82 ->  0.56 ( -95%) floor 0.25 stage 93 s
    neighbour_mode                       force    seed 4: neighbour_mode                       high   E 120.72 ->  1.80 ( -99%) floor 0.18 stage 77 s
    joint_settling                       force    seed 4: joint_settling                       high   E   9.87 ->  0.58 ( -94%) floor 0.25 stage 80 s
    channel_delay                        force    seed 4: channel_delay                        high   E  33.07 ->  0.68 ( -98%) floor 0.24 stage 72 s
    elastic_softening+cubic_stiffening   force    seed 4: cubic_stiffening                     high   E   9.38 ->  0.88 ( -91%) floor 0.33 stage 74 s
    contact_spring                       force    seed 4: unexplained                          low    E  19.44 -> 11.40 ( -41%) floor 0.36 stage 56 s
    none                                 voltage  seed 4: none                                 high   E   1.35 ->  0.64 ( -53%) floor 0.20 stage 61 s
    elastic_softening                    voltage  seed 4: elastic_softening                    high   E   5.97 ->  0.68 ( -89%) floor 0.23 stage 79 s
    cubic_stiffening                     voltage  seed 4: cubic_stiffening                     high   E   9.17 ->  0.63 ( -93%) floor 0.20 stage 93 s
    neighbour_mode                       voltage  seed 4: neighbour_mode                       high   E  43.38 ->  0.44 ( -99%) floor 0.09 stage 105 s
    joint_settling                       voltage  seed 4: joint_settling                       high   E   7.13 ->  0.66 ( -91%) floor 0.20 stage 104 s
    channel_delay                        voltage  seed 4: channel_delay                        high   E   4.19 ->  0.89 ( -79%) floor 0.20 stage 62 s
    elastic_softening+cubic_stiffening   voltage  seed 4: cubic_stiffening+elastic_softening   high   E   7.32 ->  0.67 ( -91%) floor 0.24 stage 121 s
    contact_spring                       voltage  seed 4: unexplained                          low    E  16.45 ->  7.80 ( -53%) floor 0.24 stage 68 s
"""
import argparse
import json
import sys
import tempfile
import time
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path

import pandas as pd
import yaml

sys.path.insert(0, str(Path(__file__).parents[2]))
from tests._support.rigs import JOINTED_BEAM, SECOND_MODE, SMALL_SHAKER, levels_V, truth_curve  # noqa: E402

from jointcal.calibrate import CalibrateSettings, run_calibration  # noqa: E402
from jointcal.discrepancy import DiscrepancySettings, diagnose  # noqa: E402
from jointcal.discrepancy.stage import valley_starts  # noqa: E402
from jointcal.io import read_manifest, read_run, write_csv_atomic  # noqa: E402
from jointcal.measure.modal import measure_run  # noqa: E402
from jointcal.measure.scatter import scatter  # noqa: E402
from jointcal.synth import generate  # noqa: E402
from jointcal.validate import ValidateSettings, model_from_best, validate_runs  # noqa: E402
from jointcal.validate.drive import drive_gain  # noqa: E402

CONFIG = yaml.safe_load((Path(__file__).parents[2] / "workflow" / "config" / "config.yaml").read_text())
CASES = [
    ("none", {}),
    ("elastic_softening", {"loss_ratio": 0.3}),
    ("cubic_stiffening", {"k3": 1e6}),  # 3/4 k3 q^2 ~ 5% of k + KT at the top level (8e-3 in)
    ("neighbour_mode", {}),
    ("joint_settling", {"Fs_drift": 0.15, "KT_drift": 0.1}),
    ("channel_delay", {"tau_s": 4e-4}),
    ("elastic_softening", {"loss_ratio": 0.3, "also": {"name": "cubic_stiffening", "params": {"k3": 1e6}}}),
    ("contact_spring", {"contact_k": 300.0, "gap_in": 2e-3}),
]
ETAS = (0.5, 2.0)


def specs_of(name: str, params: dict, ref: str, seed: int) -> list[dict]:
    """The campaign as one spec per sweep rate: three levels, up, 70-130% of the mode, 2% noise."""
    f, z = truth_curve(ref, 3e-3)
    second = {**SECOND_MODE, "f_hz": 150.0, "weight_lbf": 0.25} if name == "neighbour_mode" else None
    effect = {"name": "none", "params": {}} if name == "neighbour_mode" else {
        "name": name, "params": {k: v for k, v in params.items() if k != "also"},
        **({"also": params["also"]} if "also" in params else {})}
    n = len(levels_V())  # runs per spec: each rate's spec continues the lab's sequence (a settling runs on)
    return [{"seed": 10 * seed + i, "first_sequence": 1 + n * i, "sample_rate_hz": 2048.0,
             "measurement": {"noise_fraction": 0.02},
             "sweep": {"f_start_hz": 0.7 * f, "f_stop_hz": 1.3 * f, "rate_hz_per_s": eta * (f * z) ** 2,
                       "ramp_s": 0.05, "tail_s": 1.5},
             "series": [{"level_V": v, "directions": ["up"]} for v in levels_V()],
             "assemblies": {"beam": JOINTED_BEAM}, "effect": effect,
             "rig": {"reference": ref, "shaker": SMALL_SHAKER, **({"second_mode": second} if second else {})}}
            for i, eta in enumerate(ETAS)]


def diagnose_campaign(specs: list[dict], tmp: Path, settings: DiscrepancySettings | None = None):
    """Generate (one spec per sweep rate, the runs in that order), measure, calibrate and diagnose one
    campaign; (diagnosis, wall time of the stage in s)."""
    settings = settings or DiscrepancySettings.from_config(CONFIG["discrepancy"])
    rows, envs, records, props = [], {}, [], []
    for i, spec in enumerate(specs):
        folder = tmp / f"c{i}"
        generate(spec, folder, tmp / f"truth{i}.json")
        for row in read_manifest(folder / "manifest.csv").to_dict("records"):
            rec = read_run(folder / row["file"], row)
            row = {**row, "run_id": f"s{i}_{row['run_id']}", "sequence": len(rows) + 1}
            env, _, p = measure_run(rec, row, envelopes_kw=CONFIG["envelopes"], modal_kw=CONFIG["modal"])
            rows.append(row), records.append(rec)
            props.append({**{k: row[k] for k in ("run_id", "assembly", "sequence", "direction")}, **p})
            envs[row["run_id"]] = env
    table = pd.DataFrame(props)
    write_csv_atomic(table, tmp / "modal.csv")
    write_csv_atomic(scatter(table), tmp / "scatter.csv")
    cal = CalibrateSettings.from_config(CONFIG["calibrate"])  # the workflow's defaults: the model kind follows the data
    run_calibration(tmp / "modal.csv", "beam", tmp / "cal", cal)
    best = json.loads((tmp / "cal" / "ga_best.json").read_text())
    starts = valley_starts(pd.read_csv(tmp / "cal" / "ga_history.csv"), best)
    # the validation stage, as the workflow runs it before the discrepancy stage (its time is not the stage's)
    gain = drive_gain(table)
    vrows = [{**r, "drive_gain": gain} for r in rows]
    t0 = time.perf_counter()
    with ProcessPoolExecutor(max_workers=2) as ex:
        v = validate_runs([model_from_best(best) for _ in rows], records, vrows, executor=ex,
                          settings=ValidateSettings.from_config(CONFIG.get("validate")),
                          envelopes_kw=CONFIG["envelopes"], modal_kw=CONFIG["modal"])
        print(f"    validation E {v.error['E']:.2f} ({time.perf_counter() - t0:.0f} s)", flush=True)
        t0 = time.perf_counter()
        d = diagnose("beam", envs, table, best, v.scale.to_dict(orient="records"), records, rows,
                     space=cal.resolved(best).space, settings=settings, metric_before=float(v.error["E"]),
                     validate_settings=ValidateSettings.from_config(CONFIG.get("validate")),
                     envelopes_kw=CONFIG["envelopes"], modal_kw=CONFIG["modal"],
                     frames_before=v.frames, joint_starts=starts, executor=ex,
                     log=lambda s: print("   ", s, flush=True))["diagnosis"]
    return d, time.perf_counter() - t0


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--ref", default="force,voltage")
    ap.add_argument("--seeds", default="1,2,3")
    ap.add_argument("--only", default=None)
    ap.add_argument("--out", default=None)
    ap.add_argument("--keep", default=None, help="copy each case's campaign and calibration here")
    a = ap.parse_args()
    lines = []
    for name, params in CASES:
        if a.only and name not in a.only.split(","):
            continue
        for ref in a.ref.split(","):
            for seed in map(int, a.seeds.split(",")):
                hidden = name + ("+" + params["also"]["name"] if "also" in params else "")
                with tempfile.TemporaryDirectory() as d:
                    diag, wall = diagnose_campaign(specs_of(name, params, ref, seed), Path(d))
                    if a.keep:  # one folder per case: the pair's apart from its first effect's
                        import shutil
                        shutil.copytree(d, Path(a.keep) / f"{hidden}_{ref}_{seed}", dirs_exist_ok=True)
                line = (f"{hidden:36s} {ref:8s} seed {seed}: {diag['effect']:36s} {diag['confidence']:6s} "
                        f"E {diag['metric_before']:6.2f} -> {diag['metric_after']:5.2f} "
                        f"({(diag['metric_after'] / diag['metric_before'] - 1) * 100:+4.0f}%) "
                        f"floor {diag['fast_model_floor']['E']:.2f} (per run "
                        + " ".join(f"{v:.1f}" for v in diag['fast_model_floor']['per_run'].values())
                        + f") stage {wall:.0f} s")
                print(line, flush=True)
                lines.append(line)
                if a.out:
                    Path(a.out).write_text("\n".join(lines) + "\n")


if __name__ == "__main__":
    main()
