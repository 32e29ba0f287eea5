-- seixo.lab: laboratory tests on bonded-particle specimens, PFC-style.
--   local lab = require "seixo.lab"
--   local spec = lab.specimen{dim = 3, shape = "cylinder", diameter = 0.03, height = 0.06, path = "rock.h5"}
--   local r = lab.triaxial(spec, {confining = 10e6})
--   local s = lab.series(spec, {confining = {0, 5e6, 10e6, 20e6}})   -- UCS, triaxials, Mohr-Coulomb
--
-- Its parts, one job each (lua/seixo/lab/):
--   material.lua      lab.rock: the rock's micro-parameters
--   vessel.lua        the walls a genesis packs the balls in
--   specimen.lua      lab.specimen (material genesis), lab.open
--   strain.lua        lab.lateral_strain
--   frame.lua         the platens, rates and records the walled tests share
--   compression.lua   lab.ucs, lab.triaxial (with the loading-rate control)
--   brazilian.lua     lab.brazilian
--   mohr_coulomb.lua  lab.mohr_coulomb
--   series.lua        lab.series (in turn, in processes or over MPI ranks)
--   plots.lua         the figures (gnuplot), lab.have_gnuplot
--   csv.lua           lab.write_csv
--   tables.lua        deep copies and merges of tables
--   polling.lua       rank 0's polling of the MPI ranks while it runs a test or a genesis
-- lab.calibrate is seixo.calibrate's, lab.periodic seixo.periodic.
--
-- Stresses are compression positive; strains are compression positive
-- (a lateral expansion is a negative lateral strain); volumetric strain is
-- 1 - V/V0 = 1 - (1 - ea)(1 - el)^(dim - 1), the specimen's change of volume
-- (at small strains the axial strain plus (dim - 1) lateral strains, which
-- drifts at large ones: a sand's 25 %). In 2D (disks of unit
-- thickness) stresses are per unit thickness, i.e. N/m over m: Pa.

local csv = require "seixo.lab.csv"
local material = require "seixo.lab.material"
local specimen = require "seixo.lab.specimen"
local strain = require "seixo.lab.strain"
local compression = require "seixo.lab.compression"
local brazilian = require "seixo.lab.brazilian"
local mohr_coulomb = require "seixo.lab.mohr_coulomb"
local series = require "seixo.lab.series"
local plots = require "seixo.lab.plots"

local lab = {
  rock = material.rock,
  specimen = specimen.make,
  open = specimen.open,
  lateral_strain = strain.lateral,
  ucs = compression.ucs,
  triaxial = compression.triaxial,
  brazilian = brazilian.run,
  mohr_coulomb = mohr_coulomb.fit,
  series = series.run,
  write_csv = csv.write,
  have_gnuplot = plots.have_gnuplot,
}

-- lab.calibrate (calibrate.lua): the search for micro-parameters, with the lab's figures
require("seixo.calibrate").install(lab)

-- periodic cells, without walls (lua/seixo/periodic.lua)
lab.periodic = require "seixo.periodic"

-- Errors point at the caller's line, not into the library's files (seixo.caller)
require("seixo.caller").wrap(lab)

return lab
