#pragma once
/// @file
/// Small records that the model-file fuzz targets find beside the model (the scratch folder's
/// records/), so that inputs naming a record reach the record readers: real data, trimmed to a
/// few lines with the point counts adjusted (sources: examples/records/ and the PEER and COSMOS
/// records listed in data/ground_motions/SOURCES.md).

#include <array>
#include <filesystem>
#include <utility>

#include "fuzz_support.hpp"

namespace poundsim::fuzz {

/// Writes the records into `dir`/records/ (the names the seed models use).
inline void install_records(const std::filesystem::path& dir) {
  static const std::array<std::pair<const char*, const char*>, 3> records{{
      {"elcentro_1940_elc180_g.txt",
       R"(# Imperial Valley-02, 1940-05-19, El Centro Array #9, component 180, acceleration in g.
# Provenance: ../shared/data/ground_motions/RSN6_IMPVALL.I_I-ELC180.AT2 (PEER NGA-West2 RSN 6,
# from NHERI-SimCenter/EE-UQ at 3c5339f7, sha256 ab219fe7...824d; see that folder's SOURCES.md).
# Converted to two columns (time = (k-1) * 0.01 s, the acceleration value unchanged as printed).
# time_s  acceleration_g
0.00 .9984852E-03
0.01 .9991426E-03
0.02 .9997266E-03
0.03 .1000268E-02
0.04 .1000757E-02
0.05 .1001207E-02
0.06 .1001612E-02
0.07 .1001966E-02
0.08 .1002269E-02
0.09 .1002537E-02
0.10 .1002757E-02
0.11 .1002925E-02
0.12 .1003053E-02
0.13 .1003140E-02
0.14 .1003195E-02
0.15 .1003243E-02
)"},
      {"RSN6_IMPVALL.I_I-ELC180.AT2",
       R"(PEER NGA STRONG MOTION DATABASE RECORD
Imperial Valley-02, 5/19/1940, El Centro Array #9, 180
ACCELERATION TIME SERIES IN UNITS OF G
NPTS=     20, DT=   .0100 SEC,
   .9984852E-03   .9991426E-03   .9997266E-03   .1000268E-02   .1000757E-02
   .1001207E-02   .1001612E-02   .1001966E-02   .1002269E-02   .1002537E-02
   .1002757E-02   .1002925E-02   .1003053E-02   .1003140E-02   .1003195E-02
   .1003243E-02   .1003288E-02   .1003316E-02   .1003334E-02   .1003311E-02
)"},
      {"AKBMR.BNZ.acc.V2c",
       R"(Corrected acceleration    (Format v01.20 with 13 text lines)
Record of Point MacKenzie Earthquake of Fri Nov 30, 2018 17:29 UTC
Hypocenter: 61.34640 -149.95520 H= 46km Mw=7.0
Origin: 2018/11/30 17:29:29    UTC
Statn No: 37-000011 Code:AK-BMR     UAF  Bremner River, AK, USA
Coords: 60.9677 -144.6051  Site geology:
Recorder: (see cmnt)      ( ? Chns of   3 at Sta) Sensor: (see comment)    
Rcrd start time: 2018/11/30 17:29:39.137 UTC (Q=5) RcrdId: (see comment)
Sta Chan   ?:Other   (Rcrdr Chan  ?) Location:
Raw record length = 210.000 sec, Uncor max =    101730, at  82.680 sec.
Processed:2019-03-03 05:46:55 GMT, UNKN, Max =   -6.852 cm/sec2 at   76.215 sec
Record filtered below  0.03 Hz (periods over 33.33 secs), and above 20.0 Hz
Values used when parameter or data value is unknown/unspecified:   -999, -999.00
 100 Integer-header values follow on  10 lines, Format= (10I8)
       2       1       4     120       1    -999    -999      11    -999    -999
      37      37    -999       2    -999       1    -999    -999       4    -999
    -999    -999       3    -999    -999    -999    -999    -999    -999    1000
       3    -999    -999    -999       0       0    -999    -999    -999    2018
     334      11      30      17      29       5       5    -999    -999    -999
    -999     900    -999       0    -999    -999    -999    -999    -999    -999
       5       5    -999       1    -999    -999    -999    -999    -999    -999
    -999    -999    -999    -999       1       0    -999    -999    -999    -999
    -999    -999    -999    -999    -999    -999    -999    -999    -999    -999
    -999    -999    -999    -999    -999    -999    -999    -999    -999    -999
 100 Real-header values follow on  20 lines, Format= (5F15.6)
      60.967700    -144.605100     842.000000    -999.000000    -999.000000
    -999.000000    -999.000000    -999.000000    -999.000000      61.346400
    -149.955200      46.700000       7.000000    -999.000000    -999.000000
    -999.000000     290.060822      98.347414    -999.000000    -999.000000
    -999.000000       2.384188       0.000000      30.000000     180.000000
      20.000000    -999.000000    -999.000000    -999.000000      39.137490
    -999.000000       0.000000    -999.000000       0.020000     210.000000
      18.551510    -999.000000    -999.000000    -999.000000     223.975851
       0.697089      10.010000      20.020000       2.000000      20.000000
    -999.000000       1.000000    -999.000000    -999.000000    -999.000000
    -999.000000    -999.000000    -999.000000       0.030000    -999.000000
    -999.000000      20.000000    -999.000000    -999.000000    -999.000000
    -999.000000       5.000000     210.000000      -6.851512      76.215000
      -0.000011    -999.000000       0.000807      -0.005120    -999.000000
    -999.000000    -999.000000    -999.000000    -999.000000    -999.000000
    -999.000000    -999.000000    -999.000000    -999.000000       0.000000
       0.000000       0.000000       0.000000    -999.000000       0.000000
    -999.000000    -999.000000     980.665000    -999.000000    -999.000000
    -999.000000    -999.000000    -999.000000    -999.000000    -999.000000
    -999.000000    -999.000000    -999.000000    -999.000000    -999.000000
   6 Comment line(s) follow, each starting with a "|":
| Recorder: QUANTERRA Q330 
| Sensor: KINEMETRICS EPISENSOR ES-T
| RcrdId: US.1000hyfh.AK.BMR.BNZ.--
|<SCNL>BMR.BNZ.AK.--    <AUTH> 2019/02/01 21:38:15.000
|<PROCESS> MANUAL
|<EONSET> event onset(sec)=   0.0000
      12 acceleration pts, approx    0 secs, units=cm/sec2(04),Format=(1E15.6)
   3.437285e-04
   3.438810e-04
   3.440236e-04
   3.441520e-04
   3.442641e-04
   3.443618e-04
   3.444521e-04
   3.445458e-04
   3.446538e-04
   3.447812e-04
   3.449209e-04
   3.450484e-04
End-of-data for ChanBNZ acceleration
)"},
  }};
  std::filesystem::create_directories(dir / "records");
  for (const auto& [name, text] : records) write_file(dir / "records" / name, text);
}

}  // namespace poundsim::fuzz
