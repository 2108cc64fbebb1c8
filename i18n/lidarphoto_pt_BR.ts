<?xml version="1.0" encoding="utf-8"?>
<!DOCTYPE TS>
<TS version="2.1" language="pt_BR">
    <context>
        <name>AccuracyReportAlgorithm</name>
        <message>
            <source>{0}: choose its id field ({0}_ID).</source>
            <translation>{0}: escolha o seu campo de identificador ({0}_ID).</translation>
        </message>
    </context>
    <context>
        <name>AlgorithmHelp</name>
        <message>
            <source>length (cloud CRS unit, or m when DISTANCE_UNIT is metre)</source>
            <translation>comprimento (unidade do SRC da nuvem, ou m quando DISTANCE_UNIT é metro)</translation>
        </message>
        <message>
            <source>none</source>
            <translation>nenhuma</translation>
        </message>
        <message>
            <source>any finite</source>
            <translation>qualquer valor finito</translation>
        </message>
        <message>
            <source>optional</source>
            <translation>opcional</translation>
        </message>
        <message>
            <source>required</source>
            <translation>obrigatório</translation>
        </message>
        <message>
            <source>{} to {}</source>
            <translation>{} a {}</translation>
        </message>
        <message>
            <source>default: {}</source>
            <translation>padrão: {}</translation>
        </message>
        <message>
            <source>unit: {}</source>
            <translation>unidade: {}</translation>
        </message>
        <message>
            <source>References</source>
            <translation>Referências</translation>
        </message>
        <message>
            <source>How to use</source>
            <translation>Como usar</translation>
        </message>
        <message>
            <source>values: {}</source>
            <translation>valores: {}</translation>
        </message>
        <message>
            <source>range: {}</source>
            <translation>intervalo: {}</translation>
        </message>
        <message>
            <source>Parameters</source>
            <translation>Parâmetros</translation>
        </message>
        <message>
            <source>name</source>
            <translation>nome</translation>
        </message>
        <message>
            <source>meaning</source>
            <translation>significado</translation>
        </message>
        <message>
            <source>default</source>
            <translation>padrão</translation>
        </message>
        <message>
            <source>unit</source>
            <translation>unidade</translation>
        </message>
        <message>
            <source>valid range</source>
            <translation>intervalo válido</translation>
        </message>
        <message>
            <source>POINTS = the surveyed control, PHOTOS = ground photos of each point with and without the control plate, CAMERA = the ground camera; OUTPUT_FOLDER = one chip per point at the GSD of the aerial images</source>
            <translation>POINTS = o controle levantado, PHOTOS = fotos terrestres de cada ponto com e sem a placa de controle, CAMERA = a câmera terrestre; OUTPUT_FOLDER = um recorte (chip) por ponto no GSD das imagens aéreas</translation>
        </message>
        <message>
            <source>CHIPS = one GeoTIFF chip per control point, CONTROL_POINTS, CAMERA, approximate EO, IMAGES; OUTPUT = the control points' image observations, without clicking them</source>
            <translation>CHIPS = um recorte (chip) GeoTIFF por ponto de controle, CONTROL_POINTS, CAMERA, EO aproximada, IMAGES; OUTPUT = as observações de imagem dos pontos de controle, sem clicar neles</translation>
        </message>
        <message>
            <source>INPUT = the classified cloud; OUTPUT_CSV = the plane table, OUTPUT_CLOUD = the cloud with plane_id</source>
            <translation>INPUT = a nuvem classificada; OUTPUT_CSV = a tabela de planos, OUTPUT_CLOUD = a nuvem com plane_id</translation>
        </message>
        <message>
            <source>Boresight calibration with LiDAR control (Pedrosa &amp; dos Santos 2020)</source>
            <translation>Calibração de boresight com controle LiDAR (Pedrosa &amp; dos Santos 2020)</translation>
        </message>
        <message>
            <source>Monoplotting on a LiDAR surface (dos Santos, Dal Poz &amp; Dalmolin 2010)</source>
            <translation>Monorrestituição sobre uma superfície LiDAR (dos Santos, Dal Poz &amp; Dalmolin 2010)</translation>
        </message>
        <message>
            <source>Aerial triangulation and orthophotos</source>
            <translation>Aerotriangulação e ortofotos</translation>
        </message>
        <message>
            <source>A COLMAP block: orthophotos on the LiDAR DSM, and back to COLMAP</source>
            <translation>Um bloco COLMAP: ortofotos sobre o MDS LiDAR, e de volta ao COLMAP</translation>
        </message>
        <message>
            <source>An OpenSfM / ODM block: orthophotos on the LiDAR DSM</source>
            <translation>Um bloco OpenSfM / ODM: ortofotos sobre o MDS LiDAR</translation>
        </message>
        <message>
            <source>A Metashape block: orthophotos on the LiDAR DSM</source>
            <translation>Um bloco do Metashape: ortofotos sobre o MDS LiDAR</translation>
        </message>
        <message>
            <source>Boresight calibration without hand picks (automatic)</source>
            <translation>Calibração de boresight sem medições manuais (automática)</translation>
        </message>
        <message>
            <source>A Pix4D block: orthophotos on the LiDAR DSM</source>
            <translation>Um bloco do Pix4D: ortofotos sobre o MDS LiDAR</translation>
        </message>
        <message>
            <source>Boresight calibration from an SBET (or ASCII export) and the camera events</source>
            <translation>Calibração de boresight a partir de um SBET (ou exportação ASCII) e dos eventos da câmera</translation>
        </message>
        <message>
            <source>Boresight calibration with surveyed ground control located automatically</source>
            <translation>Calibração de boresight com pontos de apoio levantados e localizados automaticamente</translation>
        </message>
        <message>
            <source>LiDAR control for a whole block of tiles (dask.distributed)</source>
            <translation>Controle LiDAR para um bloco inteiro de tiles (dask.distributed)</translation>
        </message>
        <message>
            <source>Accepting a LiDAR survey (ASPRS Ed. 2: swath and vertical accuracy)</source>
            <translation>Aceitação de um levantamento LiDAR (ASPRS Ed. 2: acurácia entre faixas e vertical)</translation>
        </message>
        <message>
            <source>Terrestrial laser scanner calibration (Lichti 2007)</source>
            <translation>Calibração de laser scanner terrestre (Lichti 2007)</translation>
        </message>
        <message>
            <source>INPUT = the GNSS/INS trajectory CSV; OUTPUT_CSV = the exterior orientation of every image</source>
            <translation>INPUT = o CSV da trajetória GNSS/INS; OUTPUT_CSV = a orientação exterior de cada imagem</translation>
        </message>
        <message>
            <source>INPUT = the LAS/LAZ; OUTPUT_CLOUD = the cloud classified into ground (2) and non-ground</source>
            <translation>INPUT = o LAS/LAZ; OUTPUT_CLOUD = a nuvem classificada em terreno (2) e não terreno</translation>
        </message>
        <message>
            <source>PLANES and CLOUD = the two outputs of extractroofplanes; POINTS_CSV and LINES_CSV = LiDAR control points and lines</source>
            <translation>PLANES e CLOUD = as duas saídas de extractroofplanes; POINTS_CSV e LINES_CSV = pontos e linhas de controle LiDAR</translation>
        </message>
        <message>
            <source>TRAJECTORY = the exterior orientation, PLANES / LINES / LCPS = the control, OBSERVATIONS = image measurements made in the picking dock; OUTPUT_TABLE = boresight per group, OUTPUT_EO = corrected orientation</source>
            <translation>TRAJECTORY = a orientação exterior, PLANES / LINES / LCPS = o controle, OBSERVATIONS = medições nas imagens feitas no painel de medição; OUTPUT_TABLE = boresight por grupo, OUTPUT_EO = orientação corrigida</translation>
        </message>
        <message>
            <source>INPUT = check points measured with the corrected orientation; OUTPUT_HTML and OUTPUT_JSON = the accuracy figures against the standards</source>
            <translation>INPUT = pontos de verificação medidos com a orientação corrigida; OUTPUT_HTML e OUTPUT_JSON = os valores de acurácia em relação às normas</translation>
        </message>
        <message>
            <source>INPUT = the LAS/LAZ; OUTPUT_DTM = the terrain model (or use the cloud itself as DSM)</source>
            <translation>INPUT = o LAS/LAZ; OUTPUT_DTM = o modelo do terreno (ou use a própria nuvem como MDS)</translation>
        </message>
        <message>
            <source>OUTPUT_CSV = roof planes, used by monoplot for points on roofs</source>
            <translation>OUTPUT_CSV = planos de telhado, usados por monoplot para pontos sobre telhados</translation>
        </message>
        <message>
            <source>OBSERVATIONS + CONTROL_POINTS (or lines) of one image; OUTPUT_EO = its exterior orientation</source>
            <translation>OBSERVATIONS + CONTROL_POINTS (ou linhas) de uma imagem; OUTPUT_EO = a sua orientação exterior</translation>
        </message>
        <message>
            <source>OBSERVATIONS of the image, EO, DSM (raster or LAS/LAZ), optional PLANES; OUTPUT_CSV = 3D points</source>
            <translation>OBSERVATIONS da imagem, EO, DSM (raster ou LAS/LAZ), PLANES opcional; OUTPUT_CSV = pontos 3D</translation>
        </message>
        <message>
            <source>INPUT = monoplotted check points against their reference</source>
            <translation>INPUT = pontos de verificação monorrestituídos comparados com a sua referência</translation>
        </message>
        <message>
            <source>IMAGES = views of a chessboard or ChArUco target; OUTPUT_CAMERA = the camera JSON (start values for the block, or held fixed)</source>
            <translation>IMAGES = vistas de um alvo xadrez ou ChArUco; OUTPUT_CAMERA = o JSON da câmera (valores iniciais para o bloco, ou mantidos fixos)</translation>
        </message>
        <message>
            <source>IMAGES (and the approximate EO + CAMERA to pair images by their footprints); OUTPUT_OBSERVATIONS = tie points for the bundle</source>
            <translation>IMAGES (e a EO aproximada + CAMERA para formar pares de imagens pelas suas projeções no terreno); OUTPUT_OBSERVATIONS = pontos de enlace para o ajustamento por feixes de raios</translation>
        </message>
        <message>
            <source>CAMERA, OBSERVATIONS, GROUND_POINTS, EO (approximate); OUTPUT_EO = adjusted orientation, OUTPUT_CAMERA = calibrated camera</source>
            <translation>CAMERA, OBSERVATIONS, GROUND_POINTS, EO (aproximada); OUTPUT_EO = orientação ajustada, OUTPUT_CAMERA = câmera calibrada</translation>
        </message>
        <message>
            <source>OUTPUT_DTM = the terrain for the orthophotos</source>
            <translation>OUTPUT_DTM = o terreno para as ortofotos</translation>
        </message>
        <message>
            <source>CAMERA and EO from the bundle, IMAGES, DSM = the DTM or DSM; OUTPUT_FOLDER = one orthophoto per image</source>
            <translation>CAMERA e EO do ajustamento por feixes de raios, IMAGES, DSM = o MDT ou MDS; OUTPUT_FOLDER = uma ortofoto por imagem</translation>
        </message>
        <message>
            <source>ORTHOPHOTOS = that folder; OUTPUT = the mosaic, SEAMLINES_CSV = the region of each image</source>
            <translation>ORTHOPHOTOS = essa pasta; OUTPUT = o mosaico, SEAMLINES_CSV = a região de cada imagem</translation>
        </message>
        <message>
            <source>INPUT = check points measured on the mosaic</source>
            <translation>INPUT = pontos de verificação medidos no mosaico</translation>
        </message>
        <message>
            <source>INPUT = the model's cameras.txt or cameras.bin; FRAME = the frame of its coordinates (LOCAL, ECEF with CRS, or a CRS); OUTPUT_CAMERA, OUTPUT_EO, OUTPUT_OBSERVATIONS, OUTPUT_POINTS</source>
            <translation>INPUT = o cameras.txt ou cameras.bin do modelo; FRAME = o referencial de suas coordenadas (LOCAL, ECEF com CRS, ou um CRS); OUTPUT_CAMERA, OUTPUT_EO, OUTPUT_OBSERVATIONS, OUTPUT_POINTS</translation>
        </message>
        <message>
            <source>CAMERA and EO from the import, IMAGES, DSM = the LiDAR DSM; OUTPUT_FOLDER = one orthophoto per image</source>
            <translation>CAMERA e EO da importação, IMAGES, DSM = o MDS LiDAR; OUTPUT_FOLDER = uma ortofoto por imagem</translation>
        </message>
        <message>
            <source>CAMERA, EO (e.g. adjusted by bundleadjustment), OBSERVATIONS and POINTS; OUTPUT_FOLDER = the COLMAP text model</source>
            <translation>CAMERA, EO (p. ex. ajustada pelo bundleadjustment), OBSERVATIONS e POINTS; OUTPUT_FOLDER = o modelo COLMAP em texto</translation>
        </message>
        <message>
            <source>INPUT = the reconstruction.json (ODM: opensfm/); CRS = the mapping CRS (empty: topocentric, LOCAL); OUTPUT_CAMERA, OUTPUT_EO, OUTPUT_OBSERVATIONS, OUTPUT_POINTS</source>
            <translation>INPUT = o reconstruction.json (ODM: opensfm/); CRS = o CRS de mapeamento (vazio: topocêntrico, LOCAL); OUTPUT_CAMERA, OUTPUT_EO, OUTPUT_OBSERVATIONS, OUTPUT_POINTS</translation>
        </message>
        <message>
            <source>CAMERA, EO (e.g. adjusted by bundleadjustment), OBSERVATIONS and POINTS; OUTPUT_FOLDER = the reconstruction.json for OpenSfM / ODM</source>
            <translation>CAMERA, EO (p. ex. ajustada por bundleadjustment), OBSERVATIONS e POINTS; OUTPUT_FOLDER = o reconstruction.json para OpenSfM / ODM</translation>
        </message>
        <message>
            <source>INPUT = the camera XML (Export Cameras, Agisoft XML); CRS = the mapping CRS (empty: the chunk's projected CRS); OUTPUT_CAMERA, OUTPUT_EO</source>
            <translation>INPUT = o XML de câmeras (Export Cameras, Agisoft XML); CRS = o SRC de mapeamento (vazio: o SRC projetado do chunk); OUTPUT_CAMERA, OUTPUT_EO</translation>
        </message>
        <message>
            <source>PLANES and CLOUD = the two outputs of extractroofplanes; LINES_CSV = the LiDAR ridge, hip and valley lines</source>
            <translation>PLANES e CLOUD = as duas saídas de extractroofplanes; LINES_CSV = as linhas LiDAR de cumeeira, espigão e rincão</translation>
        </message>
        <message>
            <source>IMAGES (and the approximate EO + CAMERA to pair images by their footprints); OUTPUT_OBSERVATIONS = tie points (optional for the next step)</source>
            <translation>IMAGES (e a OE aproximada + CAMERA para parear as imagens por suas áreas de cobertura); OUTPUT_OBSERVATIONS = pontos de enlace (opcionais para a próxima etapa)</translation>
        </message>
        <message>
            <source>IMAGES, CAMERA, TRAJECTORY, LINES, PLANES and CLOUD, TIE_POINTS; OUTPUT_TABLE = boresight per group, OUTPUT_OBSERVATIONS = the observations found</source>
            <translation>IMAGES, CAMERA, TRAJECTORY, LINES, PLANES e CLOUD, TIE_POINTS; OUTPUT_TABLE = boresight por grupo, OUTPUT_OBSERVATIONS = as observações encontradas</translation>
        </message>
        <message>
            <source>INPUT = &lt;project&gt;_calibrated_camera_parameters.txt (Pix4D's 1_initial/params, its offset beside it); CRS = the project's output CRS (empty: its _wkt.prj); OUTPUT_CAMERA, OUTPUT_EO</source>
            <translation>INPUT = &lt;project&gt;_calibrated_camera_parameters.txt (1_initial/params do Pix4D, com seu offset ao lado); CRS = o SRC de saída do projeto (vazio: seu _wkt.prj); OUTPUT_CAMERA, OUTPUT_EO</translation>
        </message>
        <message>
            <source>INPUT = the SBET, POSPac / Inertial Explorer export or CSV; EVENTS = image_id, time; OUTPUT_TRAJECTORY = the trajectory table at the events, OUTPUT_EO = the exterior orientation</source>
            <translation>INPUT = o SBET, a exportação do POSPac / Inertial Explorer ou o CSV; EVENTS = image_id, time; OUTPUT_TRAJECTORY = a tabela de trajetória nos eventos, OUTPUT_EO = a orientação exterior</translation>
        </message>
        <message>
            <source>TRAJECTORY = that trajectory table, OBSERVATIONS = image measurements of the control; OUTPUT_TABLE = boresight per group</source>
            <translation>TRAJECTORY = essa tabela de trajetória, OBSERVATIONS = medições do controle nas imagens; OUTPUT_TABLE = boresight por grupo</translation>
        </message>
        <message>
            <source>OBSERVATIONS = those control rows, GROUND_POINTS = the surveyed points (role control or check), TRAJECTORY; OUTPUT_TABLE = boresight per group, OUTPUT_EO = corrected orientation</source>
            <translation>OBSERVATIONS = essas linhas control, GROUND_POINTS = os pontos levantados (role control ou check), TRAJECTORY; OUTPUT_TABLE = boresight por grupo, OUTPUT_EO = orientação corrigida</translation>
        </message>
        <message>
            <source>INPUT = a folder of LAS/LAZ tiles or a .vpc; OUTPUT_FOLDER = classified tiles, block.vpc, planes.csv, lcps.csv and lines.csv</source>
            <translation>INPUT = uma pasta de tiles LAS/LAZ ou um .vpc; OUTPUT_FOLDER = tiles classificados, block.vpc, planes.csv, lcps.csv e lines.csv</translation>
        </message>
        <message>
            <source>PLANES / LINES / LCPS = the block's tables, TRAJECTORY and OBSERVATIONS as above</source>
            <translation>PLANES / LINES / LCPS = as tabelas do bloco, TRAJECTORY e OBSERVATIONS como acima</translation>
        </message>
        <message>
            <source>INPUT = the survey's LAS/LAZ (ground classified), CHECKPOINTS = surveyed points with land cover; OUTPUT_HTML = swath overlap, within-swath and NVA/VVA verdicts, OUTPUT_CHECKPOINTS = the check points with LiDAR heights</source>
            <translation>INPUT = os LAS/LAZ do levantamento (solo classificado), CHECKPOINTS = pontos levantados com a cobertura do solo; OUTPUT_HTML = os veredictos de sobreposição entre faixas, dentro da faixa e NVA/VVA, OUTPUT_CHECKPOINTS = os pontos de verificação com as alturas LiDAR</translation>
        </message>
        <message>
            <source>INPUT = that check-point table; OUTPUT_HTML = the NSSDA and PEC-PCD sections of the LiDAR's vertical accuracy</source>
            <translation>INPUT = essa tabela de pontos de verificação; OUTPUT_HTML = as seções NSSDA e PEC-PCD da acurácia vertical do LiDAR</translation>
        </message>
        <message>
            <source>SCANS = the station clouds, CONTROL = target ids; OUTPUT = target observations</source>
            <translation>SCANS = as nuvens das estações, CONTROL = ids dos alvos; OUTPUT = observações dos alvos</translation>
        </message>
        <message>
            <source>OBSERVATIONS = those targets, CONTROL and STATIONS; OUTPUT_APS = the scanner's additional parameters, OUTPUT_HTML = the report</source>
            <translation>OBSERVATIONS = esses alvos, CONTROL e STATIONS; OUTPUT_APS = os parâmetros adicionais do scanner, OUTPUT_HTML = o relatório</translation>
        </message>
        <message>
            <source>(this algorithm)</source>
            <translation>(este algoritmo)</translation>
        </message>
        <message>
            <source>unit, range</source>
            <translation type="vanished">unidade, intervalo</translation>
        </message>
    </context>
    <context>
        <name>AutoCalibrationController</name>
        <message>
            <source>An automatic calibration is already running.</source>
            <translation>Uma calibração automática já está em execução.</translation>
        </message>
        <message>
            <source>images</source>
            <translation>imagens</translation>
        </message>
        <message>
            <source>a camera</source>
            <translation>uma câmera</translation>
        </message>
        <message>
            <source>a trajectory</source>
            <translation>uma trajetória</translation>
        </message>
        <message>
            <source>LiDAR lines</source>
            <translation>linhas LiDAR</translation>
        </message>
        <message>
            <source>The automatic calibration needs {}.</source>
            <translation>A calibração automática precisa de {}.</translation>
        </message>
        <message>
            <source>Automatic boresight calibration</source>
            <translation>Calibração de boresight automática</translation>
        </message>
        <message>
            <source>Calibration cancelled.</source>
            <translation>Calibração cancelada.</translation>
        </message>
        <message>
            <source>Automatic calibration failed. {}</source>
            <translation>A calibração automática falhou. {}</translation>
        </message>
        <message>
            <source>{} line points, {} tie points on roof planes, {} rounds</source>
            <translation>{} pontos em linhas, {} pontos de enlace em planos de telhado, {} rodadas</translation>
        </message>
        <message>
            <source>Automatic calibration done: {}</source>
            <translation>Calibração automática concluída: {}</translation>
        </message>
    </context>
    <context>
        <name>BaseAlgorithm</name>
        <message>
            <source>out of memory; nothing was written (use a coarser cell or a smaller input)</source>
            <translation>memória insuficiente; nada foi gravado (use uma célula maior ou uma entrada menor)</translation>
        </message>
        <message>
            <source>No PDF of {}: {}</source>
            <translation>Sem PDF de {}: {}</translation>
        </message>
        <message>
            <source>Report as PDF: {}</source>
            <translation>Relatório em PDF: {}</translation>
        </message>
        <message>
            <source>Cancelled by the user</source>
            <translation>Cancelado pelo usuário</translation>
        </message>
    </context>
    <context>
        <name>BundleController</name>
        <message>
            <source>A bundle adjustment is already running.</source>
            <translation>Um ajustamento por feixes de raios já está em execução.</translation>
        </message>
        <message>
            <source>Choose the camera and the exterior orientation.</source>
            <translation>Escolha a câmera e a orientação exterior.</translation>
        </message>
        <message>
            <source>The observations could not be saved.</source>
            <translation>Não foi possível salvar as observações.</translation>
        </message>
        <message>
            <source>Bundle adjustment refused: {}</source>
            <translation>Ajustamento por feixes de raios recusado: {}</translation>
        </message>
        <message>
            <source>Bundle adjustment refused: tie or control points are measured in {} open image(s); a block needs two or more. {}</source>
            <translation>Ajustamento por feixes de raios recusado: pontos de enlace ou de controle estão medidos em {} imagem(ns) aberta(s); um bloco precisa de duas ou mais. {}</translation>
        </message>
        <message>
            <source>Bundle adjustment of {} images</source>
            <translation>Ajustamento por feixes de raios de {} imagens</translation>
        </message>
        <message>
            <source>Bundle adjustment cancelled.</source>
            <translation>Ajustamento por feixes de raios cancelado.</translation>
        </message>
        <message>
            <source>Bundle adjustment failed. {}</source>
            <translation>O ajustamento por feixes de raios falhou. {}</translation>
        </message>
        <message>
            <source>Bundle adjustment done: sigma0 {}; {}</source>
            <translation>Ajustamento por feixes de raios concluído: sigma0 {}; {}</translation>
        </message>
    </context>
    <context>
        <name>BundlePanel</name>
        <message>
            <source>The dock's orientations are observations (σ {} m, {}°)</source>
            <translation>As orientações do painel são observações (σ {} m, {}°)</translation>
        </message>
        <message>
            <source>Off: approximate values only (the datum comes from the control points)</source>
            <translation>Desligado: apenas valores aproximados (o referencial vem dos pontos de controle)</translation>
        </message>
        <message>
            <source>Bundle adjustment of the open images</source>
            <translation>Ajustamento por feixes de raios das imagens abertas</translation>
        </message>
        <message>
            <source>Runs {} in the background: tie points, LCPs as control points (with their sigmas) and check points of the images open in the dock</source>
            <translation>Executa {} em segundo plano: pontos de enlace, LCPs como pontos de controle (com seus desvios-padrão) e pontos de verificação das imagens abertas no painel</translation>
        </message>
        <message>
            <source>Additional parameters</source>
            <translation>Parâmetros adicionais</translation>
        </message>
        <message>
            <source>Bundle adjustment running…</source>
            <translation>Ajustamento por feixes de raios em execução…</translation>
        </message>
        <message>
            <source>&lt;b&gt;{}&lt;/b&gt;: σ0 {:.3f}, redundancy {}, χ² test {}; {} image(s), {} measurement(s), {} rejected</source>
            <translation>&lt;b&gt;{}&lt;/b&gt;: σ0 {:.3f}, redundância {}, teste χ² {}; {} imagem(ns), {} medição(ões), {} rejeitada(s)</translation>
        </message>
        <message>
            <source>passed</source>
            <translation>aprovado</translation>
        </message>
        <message>
            <source>FAILED</source>
            <translation>REPROVADO</translation>
        </message>
        <message>
            <source>Left out: {}</source>
            <translation>Deixado de fora: {}</translation>
        </message>
        <message>
            <source>Check points ({}): RMS 3D {:.3f} m</source>
            <translation>Pontos de verificação ({}): RMS 3D {:.3f} m</translation>
        </message>
        <message>
            <source>parameter</source>
            <translation>parâmetro</translation>
        </message>
        <message>
            <source>value</source>
            <translation>valor</translation>
        </message>
        <message>
            <source>significant</source>
            <translation>significativo</translation>
        </message>
        <message>
            <source>dropped</source>
            <translation>descartado</translation>
        </message>
        <message>
            <source>fixed</source>
            <translation>fixo</translation>
        </message>
        <message>
            <source>image</source>
            <translation>imagem</translation>
        </message>
        <message>
            <source>RMS col px</source>
            <translation>RMS col px</translation>
        </message>
        <message>
            <source>RMS row px</source>
            <translation>RMS lin px</translation>
        </message>
    </context>
    <context>
        <name>CalibrationController</name>
        <message>
            <source>A calibration is already running.</source>
            <translation>Uma calibração já está em execução.</translation>
        </message>
        <message>
            <source>No observations to calibrate with.</source>
            <translation>Não há observações para calibrar.</translation>
        </message>
        <message>
            <source>Choose the plane, line or LCP layer of the observed types.</source>
            <translation>Escolha a camada de planos, de linhas ou de LCPs dos tipos observados.</translation>
        </message>
        <message>
            <source>Boresight calibration</source>
            <translation>Calibração de boresight</translation>
        </message>
        <message>
            <source>Calibration cancelled.</source>
            <translation>Calibração cancelada.</translation>
        </message>
        <message>
            <source>Calibration failed. {}</source>
            <translation>A calibração falhou. {}</translation>
        </message>
        <message>
            <source>Calibration done: {}</source>
            <translation>Calibração concluída: {}</translation>
        </message>
    </context>
    <context>
        <name>CalibrationPanel</name>
        <message>
            <source>Trajectory CSV (*.csv *.txt)</source>
            <translation>Trajetória CSV (*.csv *.txt)</translation>
        </message>
        <message>
            <source>CSV (*.csv)</source>
            <translation>CSV (*.csv)</translation>
        </message>
        <message>
            <source>Optional: its rows replace the layer's features of the same id (with their full covariance) in the overlays and the calibration</source>
            <translation>Opcional: suas linhas substituem as feições da camada com o mesmo identificador (com a covariância completa) nas sobreposições e na calibração</translation>
        </message>
        <message>
            <source>Run boresight calibration</source>
            <translation>Executar a calibração de boresight</translation>
        </message>
        <message>
            <source>Runs {} in the background with the current observations</source>
            <translation>Executa {} em segundo plano com as observações atuais</translation>
        </message>
        <message>
            <source>Calibrate automatically</source>
            <translation>Calibrar automaticamente</translation>
        </message>
        <message>
            <source>Runs {} in the background on the open images: no picked observation needed (image edges along the LiDAR lines of the line layer or table)</source>
            <translation>Executa {} em segundo plano nas imagens abertas: nenhuma observação medida à mão é necessária (bordas da imagem ao longo das linhas LiDAR da camada ou tabela de linhas)</translation>
        </message>
        <message>
            <source>Show with the calibrated orientation</source>
            <translation>Mostrar com a orientação calibrada</translation>
        </message>
        <message>
            <source>Overlays, predictions and monoplotting with the exterior orientation of the last calibration (its file, eo_calibrated.csv, becomes the Project tab's)</source>
            <translation>Sobreposições, predições e monorrestituição com a orientação exterior da última calibração (seu arquivo, eo_calibrated.csv, passa a ser o da aba Projeto)</translation>
        </message>
        <message>
            <source>Trajectory</source>
            <translation>Trajetória</translation>
        </message>
        <message>
            <source>Lever arm x,y,z (m)</source>
            <translation>Braço de alavanca x,y,z (m)</translation>
        </message>
        <message>
            <source>Mount</source>
            <translation>Montagem</translation>
        </message>
        <message>
            <source>Initial boresight (deg)</source>
            <translation>Boresight inicial (graus)</translation>
        </message>
        <message>
            <source>Plane table</source>
            <translation>Tabela de planos</translation>
        </message>
        <message>
            <source>Line table</source>
            <translation>Tabela de linhas</translation>
        </message>
        <message>
            <source>LCP table</source>
            <translation>Tabela de LCPs</translation>
        </message>
        <message>
            <source>Calibration running…</source>
            <translation>Calibração em execução…</translation>
        </message>
        <message>
            <source>{} residuals: RMS {:.2f} px, max {:.2f} px</source>
            <translation>{} resíduos: RMS {:.2f} px, máx. {:.2f} px</translation>
        </message>
    </context>
    <context>
        <name>DependencyDialog</name>
        <message>
            <source>Missing Python packages: {names}.</source>
            <translation>Pacotes Python ausentes: {names}.</translation>
        </message>
        <message>
            <source>Install...</source>
            <translation>Instalar...</translation>
        </message>
        <message>
            <source>LiDAR Photogrammetry: missing Python packages</source>
            <translation>Fotogrametria LiDAR: pacotes Python ausentes</translation>
        </message>
        <message>
            <source>The algorithms need these Python packages in the Python QGIS runs: {names}. Install them with this command, or press Install.</source>
            <translation>Os algoritmos precisam destes pacotes Python no Python que o QGIS executa: {names}. Instale-os com este comando ou clique em Instalar.</translation>
        </message>
        <message>
            <source>Copy command</source>
            <translation>Copiar comando</translation>
        </message>
        <message>
            <source>Install</source>
            <translation>Instalar</translation>
        </message>
        <message>
            <source>The command is on the clipboard.</source>
            <translation>O comando foi copiado para a área de transferência.</translation>
        </message>
        <message>
            <source>Installing...</source>
            <translation>Instalando...</translation>
        </message>
        <message>
            <source>Installed. The algorithms can run now.</source>
            <translation>Instalado. Os algoritmos já podem ser executados.</translation>
        </message>
        <message>
            <source>pip finished, but {names} still cannot be imported: restart QGIS, or see pip's output below.</source>
            <translation>O pip terminou, mas {names} ainda não pode ser importado: reinicie o QGIS ou veja a saída do pip abaixo.</translation>
        </message>
        <message>
            <source>pip failed (exit code {code}); its message is below.</source>
            <translation>O pip falhou (código de saída {code}); a mensagem dele está abaixo.</translation>
        </message>
    </context>
    <context>
        <name>GroundFilterMethodAlgorithm</name>
        <message>
            <source>Ground filter: SMRF (Pingel et al. 2013)</source>
            <translation>Filtro de terreno: SMRF (Pingel et al. 2013)</translation>
        </message>
        <message>
            <source>Ground filter: progressive morphological (Zhang et al. 2003)</source>
            <translation>Filtro de terreno: morfológico progressivo (Zhang et al. 2003)</translation>
        </message>
        <message>
            <source>Ground filter: cloth simulation (Zhang et al. 2016)</source>
            <translation>Filtro de terreno: simulação de tecido (Zhang et al. 2016)</translation>
        </message>
    </context>
    <context>
        <name>ImageLoader</name>
        <message>
            <source>{path}: read failed ({error})</source>
            <translation>{path}: falha na leitura ({error})</translation>
        </message>
    </context>
    <context>
        <name>ImagePickingDock</name>
        <message>
            <source>&lt;b&gt;Picking&lt;/b&gt;: choose the type, then left-click in the image. &lt;i&gt;tie&lt;/i&gt; and &lt;i&gt;paper&lt;/i&gt; points take the roof plane under the cursor (a menu asks when outlines overlap); &lt;i&gt;line&lt;/i&gt;: two clicks, the image line's ends, on the LiDAR line nearest to the first (drawn solid while measuring; Esc cancels, Ctrl+Z removes both ends; the Resection tab can refine the ends onto the image's edge); &lt;i&gt;lcp&lt;/i&gt;/&lt;i&gt;check&lt;/i&gt; take the nearest control point. &lt;b&gt;Resect&lt;/b&gt; (Resection tab) orients the image shown from its lines and control points; &lt;b&gt;Bundle&lt;/b&gt; (Bundle tab) adjusts the open images from their tie, control (lcp) and check points. After a tie point the other images show its prediction (yellow x): Enter accepts it, a click puts it where you see it, Esc drops it.&lt;br&gt;&lt;b&gt;Monoplot&lt;/b&gt; (needs a DSM in the Project tab): while the button is on, a click makes a 3D point on the DSM, or a vertex of a 3D line (Enter, a double click or &lt;i&gt;Finish line&lt;/i&gt; ends it); they appear on the map at once, and the save button writes them to a GeoPackage. Off: clicks measure observations again.&lt;br&gt;&lt;b&gt;Keys&lt;/b&gt;: PgDown/PgUp next/previous image · Enter accept prediction · Esc cancel prediction · Delete delete selected point · Ctrl+Z undo · Ctrl+Shift+Z / Ctrl+Y redo · T/P/L/C/K picking type · </source>
            <translation>&lt;b&gt;Medição&lt;/b&gt;: escolha o tipo e clique com o botão esquerdo na imagem. Pontos &lt;i&gt;tie&lt;/i&gt; (de enlace) e &lt;i&gt;paper&lt;/i&gt; tomam o plano de telhado sob o cursor (um menu pergunta quando os contornos se sobrepõem); &lt;i&gt;line&lt;/i&gt;: dois cliques, as extremidades da linha na imagem, sobre a linha LiDAR mais próxima do primeiro (desenhada em traço contínuo durante a medição; Esc cancela, Ctrl+Z remove as duas extremidades; a aba Resseção pode refinar as extremidades sobre a borda na imagem); &lt;i&gt;lcp&lt;/i&gt;/&lt;i&gt;check&lt;/i&gt; tomam o ponto de controle mais próximo. &lt;b&gt;Resseção&lt;/b&gt; (aba Resseção) orienta a imagem exibida a partir das suas linhas e pontos de controle; &lt;b&gt;Feixes&lt;/b&gt; (aba Feixes) ajusta as imagens abertas a partir dos seus pontos de enlace, de controle (lcp) e de verificação. Após um ponto de enlace, as outras imagens mostram a sua predição (x amarelo): Enter a aceita, um clique a coloca onde você a vê, Esc a descarta.&lt;br&gt;&lt;b&gt;Monorrestituir&lt;/b&gt; (requer um MDS na aba Projeto): enquanto o botão está ligado, um clique cria um ponto 3D sobre o MDS, ou um vértice de uma linha 3D (Enter, um clique duplo ou &lt;i&gt;Terminar linha&lt;/i&gt; a encerra); eles aparecem no mapa imediatamente, e o botão salvar os grava em um GeoPackage. Desligado: os cliques voltam a medir observações.&lt;br&gt;&lt;b&gt;Teclas&lt;/b&gt;: PgDown/PgUp imagem seguinte/anterior · Enter aceitar a predição · Esc cancelar a predição · Delete excluir o ponto selecionado · Ctrl+Z desfazer · Ctrl+Shift+Z / Ctrl+Y refazer · T/P/L/C/K tipo de medição · </translation>
        </message>
        <message>
            <source>Image Point Picking</source>
            <translation>Medição de Pontos na Imagem</translation>
        </message>
        <message>
            <source>Project</source>
            <translation>Projeto</translation>
        </message>
        <message>
            <source>Calibration</source>
            <translation>Calibração</translation>
        </message>
        <message>
            <source>Resection</source>
            <translation>Resseção</translation>
        </message>
        <message>
            <source>Bundle</source>
            <translation>Feixes</translation>
        </message>
        <message>
            <source>Help</source>
            <translation>Ajuda</translation>
        </message>
        <message>
            <source>Building the overview pyramid: {:.0f} %</source>
            <translation>Construindo a pirâmide de visões gerais: {:.0f} %</translation>
        </message>
        <message>
            <source>Image picking</source>
            <translation>Medição na imagem</translation>
        </message>
        <message>
            <source>{image}  col {col:.2f}  row {row:.2f}  zoom {zoom:.3g}</source>
            <translation>{image}  col {col:.2f}  lin {row:.2f}  zoom {zoom:.3g}</translation>
        </message>
    </context>
    <context>
        <name>ImageSource</name>
        <message>
            <source>{path}: its folder is read-only, no overview pyramid can be written next to it</source>
            <translation>{path}: a pasta é somente leitura, nenhuma pirâmide de visões gerais pode ser gravada ao lado da imagem</translation>
        </message>
        <message>
            <source>GDAL is not available ({error})</source>
            <translation>o GDAL não está disponível ({error})</translation>
        </message>
        <message>
            <source>{path}: overview build cancelled</source>
            <translation>{path}: construção das visões gerais cancelada</translation>
        </message>
        <message>
            <source>{path}: the image file does not exist</source>
            <translation>{path}: o arquivo de imagem não existe</translation>
        </message>
        <message>
            <source>{path}: GDAL cannot open it (no raster band)</source>
            <translation>{path}: o GDAL não consegue abri-lo (nenhuma banda raster)</translation>
        </message>
        <message>
            <source>{path}: neither GDAL nor OpenCV can read this image{why}</source>
            <translation>{path}: nem o GDAL nem o OpenCV conseguem ler esta imagem{why}</translation>
        </message>
        <message>
            <source>{path}: the image is closed</source>
            <translation>{path}: a imagem está fechada</translation>
        </message>
        <message>
            <source>{path}: cannot build the overview pyramid ({error})</source>
            <translation>{path}: não foi possível construir a pirâmide de visões gerais ({error})</translation>
        </message>
        <message>
            <source>{path}: cannot write the overview pyramid ({error})</source>
            <translation>{path}: não foi possível gravar a pirâmide de visões gerais ({error})</translation>
        </message>
        <message>
            <source>{path}: GDAL cannot open it ({error})</source>
            <translation>{path}: o GDAL não consegue abri-lo ({error})</translation>
        </message>
        <message>
            <source>{path}: read failed</source>
            <translation>{path}: falha na leitura</translation>
        </message>
        <message>
            <source>{path}: read failed ({error})</source>
            <translation>{path}: falha na leitura ({error})</translation>
        </message>
    </context>
    <context>
        <name>ImageView</name>
        <message>
            <source>Wheel: zoom about the cursor · middle/right drag or Space+drag: pan · left click: pick · left drag on a point: move it · +/-: zoom · F: fit · 1: 100 % · M: magnifier · arrows: pan</source>
            <translation>Roda: zoom em torno do cursor · arrastar com o botão do meio/direito ou Espaço+arrastar: deslocar · clique esquerdo: medir · arrastar um ponto com o botão esquerdo: movê-lo · +/-: zoom · F: ajustar · 1: 100 % · M: lupa · setas: deslocar</translation>
        </message>
        <message>
            <source>Reading a preview of {}…</source>
            <translation>Lendo uma pré-visualização de {}…</translation>
        </message>
        <message>
            <source>Building the overview pyramid of {}: {:.0f} %</source>
            <translation>Construindo a pirâmide de visões gerais de {}: {:.0f} %</translation>
        </message>
    </context>
    <context>
        <name>LidarPhotoPlugin</name>
        <message>
            <source>The algorithms are not loaded: {}</source>
            <translation>Os algoritmos não foram carregados: {}</translation>
        </message>
        <message>
            <source>&amp;LiDAR Photogrammetry</source>
            <translation>&amp;Fotogrametria LiDAR</translation>
        </message>
        <message>
            <source>LiDAR Photogrammetry</source>
            <translation>Fotogrametria LiDAR</translation>
        </message>
        <message>
            <source>Trajectory to Exterior Orientation…</source>
            <translation>Trajetória para Orientação Exterior…</translation>
        </message>
        <message>
            <source>Exterior orientation of each image from an INS/GNSS trajectory</source>
            <translation>Orientação exterior de cada imagem a partir de uma trajetória INS/GNSS</translation>
        </message>
        <message>
            <source>Show the Algorithms in the Processing Toolbox</source>
            <translation>Mostrar os algoritmos na Caixa de Ferramentas de Processamento</translation>
        </message>
        <message>
            <source>Image Point Picking</source>
            <translation>Medição de Pontos na Imagem</translation>
        </message>
        <message>
            <source>Measure image points on LiDAR roof planes, lines and LCPs</source>
            <translation>Medir pontos na imagem sobre planos de telhado, linhas e LCPs do LiDAR</translation>
        </message>
        <message>
            <source>The picking dock could not be loaded: {}</source>
            <translation>Não foi possível carregar o painel de medição: {}</translation>
        </message>
        <message>
            <source>The algorithm {} is not available.</source>
            <translation>O algoritmo {} não está disponível.</translation>
        </message>
        <message>
            <source>The Processing plugin is not enabled.</source>
            <translation>O complemento Processamento não está habilitado.</translation>
        </message>
    </context>
    <context>
        <name>LidarPhotoProvider</name>
        <message>
            <source>Orthophotos ({})</source>
            <translation>Ortofotos ({})</translation>
        </message>
        <message>
            <source>All files (*.*)</source>
            <translation>Todos os arquivos (*.*)</translation>
        </message>
        <message>
            <source>raster</source>
            <translation>raster</translation>
        </message>
        <message>
            <source>LAS/LAZ</source>
            <translation>LAS/LAZ</translation>
        </message>
        <message>
            <source>raster or LAS/LAZ</source>
            <translation>raster ou LAS/LAZ</translation>
        </message>
        <message>
            <source>CSV</source>
            <translation>CSV</translation>
        </message>
        <message>
            <source>{name}: the layer {layer} is not backed by a {what} file ({source}); save it as one first</source>
            <translation>{name}: a camada {layer} não está gravada em um arquivo {what} ({source}); salve-a primeiro como tal</translation>
        </message>
        <message>
            <source>LiDAR Photogrammetry</source>
            <translation>Fotogrametria LiDAR</translation>
        </message>
        <message>
            <source>LiDAR Photogrammetry Toolkit</source>
            <translation>Kit de Ferramentas de Fotogrametria LiDAR</translation>
        </message>
        <message>
            <source>{name}: the layer {layer} is not a raster or LAS/LAZ file ({source}); save it as a GeoTIFF first</source>
            <translation type="vanished">{name}: a camada {layer} não é um arquivo raster nem LAS/LAZ ({source}); salve-a primeiro como GeoTIFF</translation>
        </message>
    </context>
    <context>
        <name>Messages</name>
        <message>
            <source>Missing Python packages: {names}. The LiDAR Photogrammetry algorithms need them; install them into QGIS's Python and restart QGIS: {cmd}</source>
            <translation>Pacotes Python ausentes: {names}. Os algoritmos de Fotogrametria LiDAR precisam deles; instale-os no Python do QGIS e reinicie o QGIS: {cmd}</translation>
        </message>
        <message>
            <source>Optional Python packages not installed: {names} ({effects}). To install: {cmd}</source>
            <translation>Pacotes Python opcionais não instalados: {names} ({effects}). Para instalar: {cmd}</translation>
        </message>
    </context>
    <context>
        <name>MonoplotController</name>
        <message>
            <source>Monoplotting needs the camera and the exterior orientation (Project tab).</source>
            <translation>A monorrestituição precisa da câmera e da orientação exterior (aba Projeto).</translation>
        </message>
        <message>
            <source>Choose a DSM for monoplotting in the Project tab: a raster layer, or a GeoTIFF or LAS/LAZ file.</source>
            <translation>Escolha um MDS para a monorrestituição na aba Projeto: uma camada raster, ou um arquivo GeoTIFF ou LAS/LAZ.</translation>
        </message>
        <message>
            <source>DSM not loaded: {}</source>
            <translation>MDS não carregado: {}</translation>
        </message>
        <message>
            <source>Monoplotting {}: click in the image; the 3D features appear on the map at once.{}</source>
            <translation>Monorrestituição de {}: clique na imagem; as feições 3D aparecem no mapa imediatamente.{}</translation>
        </message>
        <message>
            <source>points</source>
            <translation>pontos</translation>
        </message>
        <message>
            <source>lines</source>
            <translation>linhas</translation>
        </message>
        <message>
            <source> Finish each line with Enter or a double click.</source>
            <translation> Termine cada linha com Enter ou um clique duplo.</translation>
        </message>
        <message>
            <source>Monoplotting off: clicks measure observations again.</source>
            <translation>Monorrestituição desligada: os cliques voltam a medir observações.</translation>
        </message>
        <message>
            <source> The line in progress was added.</source>
            <translation> A linha em andamento foi adicionada.</translation>
        </message>
        <message>
            <source>3D line of {} vertices added.</source>
            <translation>Linha 3D de {} vértices adicionada.</translation>
        </message>
        <message>
            <source>Save monoplotted features</source>
            <translation>Salvar as feições monorrestituídas</translation>
        </message>
        <message>
            <source>GeoPackage (*.gpkg)</source>
            <translation>GeoPackage (*.gpkg)</translation>
        </message>
        <message>
            <source>Not saved: {}</source>
            <translation>Não salvo: {}</translation>
        </message>
        <message>
            <source>Saved {} to {}.</source>
            <translation>{} salvo(s) em {}.</translation>
        </message>
        <message>
            <source>Nothing monoplotted yet.</source>
            <translation>Nada foi monorrestituído ainda.</translation>
        </message>
    </context>
    <context>
        <name>MonoplotTool</name>
        <message>
            <source>The DSM was in '{}': resampled into '{}' (cell {:g}) for monoplotting.</source>
            <translation>O MDS estava em '{}': reamostrado em '{}' (célula {:g}) para a monorrestituição.</translation>
        </message>
        <message>
            <source>Load the camera, the orientation and a DSM first</source>
            <translation>Carregue primeiro a câmera, a orientação e um MDS</translation>
        </message>
        <message>
            <source>Image {} has no exterior orientation: nothing to monoplot.</source>
            <translation>A imagem {} não tem orientação exterior: nada a monorrestituir.</translation>
        </message>
        <message>
            <source>Line vertex {} (Enter or a double click ends the line).</source>
            <translation>Vértice de linha {} (Enter ou um clique duplo termina a linha).</translation>
        </message>
        <message>
            <source>3D point {:.3f}, {:.3f}, {:.3f} (sigma Z {:.3f} m, {}).</source>
            <translation>Ponto 3D {:.3f}, {:.3f}, {:.3f} (sigma Z {:.3f} m, {}).</translation>
        </message>
        <message>
            <source>No 3D point: {}.</source>
            <translation>Nenhum ponto 3D: {}.</translation>
        </message>
        <message>
            <source>A line needs two vertices or more.</source>
            <translation>Uma linha precisa de dois vértices ou mais.</translation>
        </message>
        <message>
            <source>Monoplotted points</source>
            <translation>Pontos monorrestituídos</translation>
        </message>
        <message>
            <source>Monoplotted lines</source>
            <translation>Linhas monorrestituídas</translation>
        </message>
    </context>
    <context>
        <name>ObservationModel</name>
        <message>
            <source>image</source>
            <translation>imagem</translation>
        </message>
        <message>
            <source>point</source>
            <translation>ponto</translation>
        </message>
        <message>
            <source>type</source>
            <translation>tipo</translation>
        </message>
        <message>
            <source>target</source>
            <translation>alvo</translation>
        </message>
        <message>
            <source>col</source>
            <translation>col</translation>
        </message>
        <message>
            <source>row</source>
            <translation>lin</translation>
        </message>
        <message>
            <source>|v| px</source>
            <translation>|v| px</translation>
        </message>
    </context>
    <context>
        <name>OverviewTask</name>
        <message>
            <source>Overview pyramid of {}</source>
            <translation>Pirâmide de visões gerais de {}</translation>
        </message>
        <message>
            <source>{path}: overview build cancelled</source>
            <translation>{path}: construção das visões gerais cancelada</translation>
        </message>
        <message>
            <source>{path}: overview build failed ({error})</source>
            <translation>{path}: falha na construção das visões gerais ({error})</translation>
        </message>
        <message>
            <source>{path}: overview pyramid built ({name})</source>
            <translation>{path}: pirâmide de visões gerais construída ({name})</translation>
        </message>
    </context>
    <context>
        <name>PickingController</name>
        <message>
            <source>plane {} ({:.1f} m away)</source>
            <translation>plano {} (a {:.1f} m)</translation>
        </message>
        <message>
            <source>No image shown.</source>
            <translation>Nenhuma imagem exibida.</translation>
        </message>
        <message>
            <source>Image {} has no orientation: picking needs the camera and the exterior orientation.</source>
            <translation>A imagem {} não tem orientação: a medição precisa da câmera e da orientação exterior.</translation>
        </message>
        <message>
            <source>No roof plane under the cursor.</source>
            <translation>Nenhum plano de telhado sob o cursor.</translation>
        </message>
        <message>
            <source>No line within {:.0f} px.</source>
            <translation>Nenhuma linha a menos de {:.0f} px.</translation>
        </message>
        <message>
            <source>No control point within {:.0f} px.</source>
            <translation>Nenhum ponto de controle a menos de {:.0f} px.</translation>
        </message>
        <message>
            <source>Line on LiDAR line {}: click its other end (Esc cancels).</source>
            <translation>Linha sobre a linha LiDAR {}: clique na outra extremidade (Esc cancela).</translation>
        </message>
        <message>
            <source>Tie {} on plane {}: predicted in {} other image(s) (Enter accepts, click corrects).</source>
            <translation>Enlace {} no plano {}: previsto em {} outra(s) imagem(ns) (Enter aceita, um clique corrige).</translation>
        </message>
        <message>
            <source>{} on plane {}.</source>
            <translation>{} no plano {}.</translation>
        </message>
        <message>
            <source>The line's ends must be 1 px apart or more.</source>
            <translation>As extremidades da linha devem estar a 1 px ou mais uma da outra.</translation>
        </message>
        <message>
            <source>Image line of LiDAR line {} measured.</source>
            <translation>Linha da imagem da linha LiDAR {} medida.</translation>
        </message>
        <message>
            <source>Select a point of the image shown first.</source>
            <translation>Selecione primeiro um ponto da imagem exibida.</translation>
        </message>
        <message>
            <source>Point {} is measured in no other image: no template.</source>
            <translation>O ponto {} não está medido em nenhuma outra imagem: sem modelo (template).</translation>
        </message>
        <message>
            <source>Point {} not refined: {}</source>
            <translation>Ponto {} não refinado: {}</translation>
        </message>
        <message>
            <source>Point {} refined by least-squares matching on image {}: moved {:.2f} px, sigma {:.3f} px, correlation {:.2f}.</source>
            <translation>Ponto {} refinado por correspondência por mínimos quadrados na imagem {}: deslocado {:.2f} px, sigma {:.3f} px, correlação {:.2f}.</translation>
        </message>
    </context>
    <context>
        <name>PipTask</name>
        <message>
            <source>Installing Python packages for LiDAR Photogrammetry</source>
            <translation>Instalando pacotes Python para a Fotogrametria LiDAR</translation>
        </message>
    </context>
    <context>
        <name>ProjectLoader</name>
        <message>
            <source>Orientation not loaded: {}</source>
            <translation>Orientação não carregada: {}</translation>
        </message>
        <message>
            <source>Control table not read: {}</source>
            <translation>Tabela de controle não lida: {}</translation>
        </message>
        <message>
            <source>{} plane(s) of {} have no heights and no a,b,c,d fields: skipped.</source>
            <translation>{} plano(s) de {} não têm alturas nem campos a,b,c,d: ignorado(s).</translation>
        </message>
        <message>
            <source>Observations not loaded: {}</source>
            <translation>Observações não carregadas: {}</translation>
        </message>
        <message>
            <source>{} observation(s) in {}.</source>
            <translation>{} observação(ões) em {}.</translation>
        </message>
        <message>
            <source>{} observation row(s) name image(s) not in the exterior orientation ({}…): is the file from another project? They are kept in the file but not shown.</source>
            <translation>{} linha(s) de observação citam imagem(ns) ausente(s) da orientação exterior ({}…): o arquivo é de outro projeto? Elas são mantidas no arquivo, mas não são exibidas.</translation>
        </message>
        <message>
            <source>The session was not fully restored: {}</source>
            <translation>A sessão não foi restaurada por completo: {}</translation>
        </message>
    </context>
    <context>
        <name>ProjectPanel</name>
        <message>
            <source>Camera JSON (*.json)</source>
            <translation>Câmera JSON (*.json)</translation>
        </message>
        <message>
            <source>EO CSV (*.csv *.txt)</source>
            <translation>OE CSV (*.csv *.txt)</translation>
        </message>
        <message>
            <source>Exterior orientation from 'Trajectory to EO'</source>
            <translation>Orientação exterior de 'Trajetória para OE'</translation>
        </message>
        <message>
            <source>Mapping CRS of the exterior orientation</source>
            <translation>SRC de mapeamento da orientação exterior</translation>
        </message>
        <message>
            <source>Add…</source>
            <translation>Adicionar…</translation>
        </message>
        <message>
            <source>Clear</source>
            <translation>Limpar</translation>
        </message>
        <message>
            <source>Observation CSV (*.csv)</source>
            <translation>Observações CSV (*.csv)</translation>
        </message>
        <message>
            <source>Saved after every change (atomic write)</source>
            <translation>Salvo após cada alteração (gravação atômica)</translation>
        </message>
        <message>
            <source>Camera</source>
            <translation>Câmera</translation>
        </message>
        <message>
            <source>Exterior orientation</source>
            <translation>Orientação exterior</translation>
        </message>
        <message>
            <source>Mapping CRS</source>
            <translation>SRC de mapeamento</translation>
        </message>
        <message>
            <source>Images</source>
            <translation>Imagens</translation>
        </message>
        <message>
            <source>Roof planes</source>
            <translation>Planos de telhado</translation>
        </message>
        <message>
            <source>Lines</source>
            <translation>Linhas</translation>
        </message>
        <message>
            <source>Control points</source>
            <translation>Pontos de controle</translation>
        </message>
        <message>
            <source>Observations</source>
            <translation>Observações</translation>
        </message>
        <message>
            <source>DSM raster (heights) for monoplotting</source>
            <translation>Raster MDS (alturas) para a monorrestituição</translation>
        </message>
        <message>
            <source>DSM (*.tif *.tiff *.las *.laz);;All files (*)</source>
            <translation>MDS (*.tif *.tiff *.las *.laz);;Todos os arquivos (*)</translation>
        </message>
        <message>
            <source>Or a DSM file: GeoTIFF, or a LAS/LAZ cloud rasterised at the cell size</source>
            <translation>Ou um arquivo de MDS: GeoTIFF, ou uma nuvem LAS/LAZ rasterizada no tamanho de célula</translation>
        </message>
        <message>
            <source> m</source>
            <translation> m</translation>
        </message>
        <message>
            <source>Cell of the DSM made from a LAS/LAZ file</source>
            <translation>Célula do MDS gerado a partir de um arquivo LAS/LAZ</translation>
        </message>
        <message>
            <source>DSM (monoplot)</source>
            <translation>MDS (monorrestituição)</translation>
        </message>
        <message>
            <source>or DSM file</source>
            <translation>ou arquivo de MDS</translation>
        </message>
        <message>
            <source>Images (*.tif *.tiff *.jpg *.jpeg *.png *.jp2 *.vrt *.img);;All files (*)</source>
            <translation>Imagens (*.tif *.tiff *.jpg *.jpeg *.png *.jp2 *.vrt *.img);;Todos os arquivos (*)</translation>
        </message>
    </context>
    <context>
        <name>Report</name>
        <message>
            <source>the global test failed with sigma0 = {sigma0:.3g} &gt; MAX_SIGMA0 {maximum:g}: the observations are {sigma0:.3g} times less precise than their sigmas say (wrong sigma_px or INS grade, or undetected blunders)</source>
            <translation>o teste global falhou com sigma0 = {sigma0:.3g} &gt; MAX_SIGMA0 {maximum:g}: as observações são {sigma0:.3g} vezes menos precisas do que dizem seus desvios-padrão (sigma_px ou classe do INS errados, ou erros grosseiros não detectados)</translation>
        </message>
        <message>
            <source>not a finite number: {items}</source>
            <translation>não é um número finito: {items}</translation>
        </message>
        <message>
            <source>{items} beyond MAX_BORESIGHT {maximum:g} deg: implausible for a misalignment (wrong MOUNT, image ids or observations?)</source>
            <translation>{items} além de MAX_BORESIGHT {maximum:g} graus: implausível para um desalinhamento (MOUNT, identificadores das imagens ou observações errados?)</translation>
        </message>
        <message>
            <source>the adjustment did not converge after {n} iterations ({why})</source>
            <translation>o ajustamento não convergiu após {n} iterações ({why})</translation>
        </message>
        <message>
            <source>the adjustment did not converge after {n} iterations</source>
            <translation>o ajustamento não convergiu após {n} iterações</translation>
        </message>
        <message>
            <source>{angle} of group {group}</source>
            <translation>{angle} do grupo {group}</translation>
        </message>
        <message>
            <source>{angle} = {value:.4f} deg in group {group}</source>
            <translation>{angle} = {value:.4f} graus no grupo {group}</translation>
        </message>
        <message>
            <source>{summary} (details: lidarphoto -vv; QGIS: Processing logging level Verbose)</source>
            <translation>{summary} (detalhes: lidarphoto -vv; QGIS: opções do Processamento, nível de log Verbose)</translation>
        </message>
        <message>
            <source>the global test failed with sigma0 = {sigma0:.3g} &gt; MAX_SIGMA0 {maximum:g}: the observations are {sigma0:.3g} times less precise than their sigmas say (wrong sigmas, a model that does not fit, or undetected blunders)</source>
            <translation>o teste global falhou com sigma0 = {sigma0:.3g} &gt; MAX_SIGMA0 {maximum:g}: as observações são {sigma0:.3g} vezes menos precisas do que os seus desvios-padrão dizem (desvios-padrão errados, um modelo que não se ajusta, ou erros grosseiros não detectados)</translation>
        </message>
        <message>
            <source>normals nearly parallel</source>
            <translation>normais quase paralelas</translation>
        </message>
        <message>
            <source>planes meet in a line, not a point</source>
            <translation>os planos se encontram em uma linha, não em um ponto</translation>
        </message>
        <message>
            <source>intersection far from a plane's points</source>
            <translation>interseção longe dos pontos de um plano</translation>
        </message>
        <message>
            <source>same corner as a more precise triple</source>
            <translation>mesmo canto que um trio mais preciso</translation>
        </message>
        <message>
            <source>no common boundary</source>
            <translation>sem borda comum</translation>
        </message>
        <message>
            <source>planes nearly parallel: no stable line</source>
            <translation>planos quase paralelos: nenhuma linha estável</translation>
        </message>
        <message>
            <source>fewer than two planes</source>
            <translation>menos de dois planos</translation>
        </message>
        <message>
            <source>{n} candidates rejected: {reasons}</source>
            <translation>{n} candidatos rejeitados: {reasons}</translation>
        </message>
        <message>
            <source>no roof plane: only {n} candidate points (fewer than needed for one plane)</source>
            <translation>nenhum plano de telhado: apenas {n} pontos candidatos (menos do que o necessário para um plano)</translation>
        </message>
        <message>
            <source>{planes} roof planes, {assigned} of {n} points assigned ({kept} kept by the local RANSAC)</source>
            <translation>{planes} planos de telhado, {assigned} de {n} pontos atribuídos ({kept} mantidos pelo RANSAC local)</translation>
        </message>
        <message>
            <source>no roof plane found among {n} points ({kept} passed the local RANSAC test): the cloud has no planar, roof-like surfaces with these parameters</source>
            <translation>nenhum plano de telhado encontrado entre {n} pontos ({kept} passaram no teste do RANSAC local): a nuvem não tem superfícies planas, semelhantes a telhados, com estes parâmetros</translation>
        </message>
        <message>
            <source>Baarda data snooping (alpha = {alpha:g} per observation, critical |w| = {critical:.2f}, iterative rejection of whole groups)</source>
            <translation>data snooping de Baarda (alfa = {alpha:g} por observação, |w| crítico = {critical:.2f}, rejeição iterativa de grupos inteiros)</translation>
        </message>
        <message>
            <source>{robust}, then {snooping}</source>
            <translation>{robust}, depois {snooping}</translation>
        </message>
        <message>
            <source>{robust}; no data snooping</source>
            <translation>{robust}; sem data snooping</translation>
        </message>
        <message>
            <source>none (data snooping disabled)</source>
            <translation>nenhuma (data snooping desativado)</translation>
        </message>
        <message>
            <source>{method} reweighting (k = {k:g} robust scale units, {rounds} rounds, robust scale {scale:.3g}), groups with a standardised misfit above {critical:.2f} set aside</source>
            <translation>reponderação {method} (k = {k:g} unidades da escala robusta, {rounds} rodadas, escala robusta {scale:.3g}), grupos com desajuste padronizado acima de {critical:.2f} afastados</translation>
        </message>
        <message>
            <source>data snooping skipped: the adjustment did not converge</source>
            <translation>data snooping não executado: o ajustamento não convergiu</translation>
        </message>
        <message>
            <source>{n} observation rows have a redundancy number of about zero and cannot be tested by data snooping</source>
            <translation>{n} linhas de observação têm número de redundância próximo de zero e não podem ser testadas pelo data snooping</translation>
        </message>
        <message>
            <source>robust estimation: setting aside the {n} groups it flagged would leave the adjustment not observable; they are kept</source>
            <translation>estimação robusta: afastar os {n} grupos que ela marcou deixaria o ajustamento não observável; eles foram mantidos</translation>
        </message>
        <message>
            <source>data snooping stopped at max_rejections = {n} with |w| = {w:.2f} still above {critical:.2f}</source>
            <translation>data snooping interrompido em max_rejections = {n} com |w| = {w:.2f} ainda acima de {critical:.2f}</translation>
        </message>
        <message>
            <source>data snooping stopped: without {block} / {label} the adjustment did not converge; it is kept</source>
            <translation>data snooping interrompido: sem {block} / {label} o ajustamento não convergiu; a observação foi mantida</translation>
        </message>
        <message>
            <source>data snooping stopped: rejecting {block} / {label} (|w| = {w:.2f}) would make the adjustment not observable; it is kept</source>
            <translation>data snooping interrompido: rejeitar {block} / {label} (|w| = {w:.2f}) tornaria o ajustamento não observável; a observação foi mantida</translation>
        </message>
        <message>
            <source>data snooping rejected {k} of {n} observations ({share:.1f} %); its false alarms at alpha = {alpha:g} explain at most {bound} ({expected:.2g} expected, P({k} or more) = {p:.2g}): a model that does not fit the data (parameters missing?) or many blunders, and the global test of the rest does not show it</source>
            <translation>o data snooping rejeitou {k} de {n} observações ({share:.1f} %); os seus falsos alarmes com alfa = {alpha:g} explicam no máximo {bound} ({expected:.2g} esperadas, P({k} ou mais) = {p:.2g}): um modelo que não se ajusta aos dados (parâmetros em falta?) ou muitos erros grosseiros, e o teste global das restantes não o mostra</translation>
        </message>
        <message>
            <source>no convergence within {n} iterations</source>
            <translation>sem convergência em {n} iterações</translation>
        </message>
        <message>
            <source>the cost could not be reduced further at iteration {iteration} (step {step:.3g} sigma): stopped without convergence</source>
            <translation>o custo não pôde ser reduzido mais na iteração {iteration} (passo de {step:.3g} sigma): interrompido sem convergência</translation>
        </message>
        <message>
            <source>no redundancy: sigma0 and the global test are undefined</source>
            <translation>sem redundância: sigma0 e o teste global ficam indefinidos</translation>
        </message>
        <message>
            <source>the camera timing offset dt cannot be separated from the lever arm's {axis} component: the velocity in the aircraft's body frame is the same at every image to {share:.1%} ({speed:.1f} m/s along body {axis}; at least {minimum:.0%} is needed), so dt times the speed equals a lever arm along {axis} (one line, or lines flown at one speed in either direction); fly lines at clearly different speeds, or keep the lever arm fixed, or do not estimate the timing.</source>
            <translation>o atraso de disparo da câmera dt não pode ser separado da componente {axis} do braço de alavanca: a velocidade no referencial do corpo da aeronave é a mesma em todas as imagens a menos de {share:.1%} ({speed:.1f} m/s ao longo de {axis} do corpo; é preciso pelo menos {minimum:.0%}), de modo que dt vezes a velocidade equivale a um braço de alavanca ao longo de {axis} (uma faixa, ou faixas voadas a uma só velocidade em qualquer sentido); voe faixas a velocidades claramente diferentes, ou mantenha o braço de alavanca fixo, ou não estime o atraso de disparo.</translation>
        </message>
        <message>
            <source>the lever arm cannot be separated from the INS position: it turns with the aircraft while a position error does not, so fly lines in opposite directions (horizontal components) and add height control (LCPs); its vertical component cannot be told from a vertical GNSS bias at all: measure it (total station) and keep it fixed.</source>
            <translation>o braço de alavanca não pode ser separado da posição do INS: ele gira com a aeronave, enquanto um erro de posição não gira; portanto, voe linhas de voo em sentidos opostos (componentes horizontais) e acrescente controle altimétrico (LCPs); sua componente vertical não pode de forma alguma ser distinguida de um viés vertical do GNSS: meça-a (estação total) e mantenha-a fixa.</translation>
        </message>
        <message>
            <source>the interior orientation is not separable: the focal length trades with the flying height (needs control at clearly different heights or two flying heights), the principal point with the boresight omega/phi (both shift the whole image); fix them from the lab calibration.</source>
            <translation>a orientação interior não é separável: a distância focal se confunde com a altura de voo (requer controle em alturas claramente diferentes ou duas alturas de voo), o ponto principal com omega/phi do boresight (ambos deslocam a imagem inteira); fixe-os pela calibração de laboratório.</translation>
        </message>
        <message>
            <source>the camera timing offset cannot be separated: on one line, or on lines flown at one speed (in either direction), dt times the speed equals an along-track lever arm (and, over flat ground, a pitch boresight); fly lines at clearly different speeds, or keep the lever arm fixed, or do not estimate the timing.</source>
            <translation>o atraso de disparo da câmera não pode ser separado: em uma faixa, ou em faixas voadas a uma mesma velocidade (em qualquer sentido), dt vezes a velocidade equivale a um braço de alavanca ao longo da trajetória (e, sobre terreno plano, a um boresight em arfagem); voe faixas a velocidades claramente diferentes, ou mantenha o braço de alavanca fixo, ou não estime o atraso.</translation>
        </message>
        <message>
            <source>some tie points are not determined: measure each in at least two images, on a plane that is not seen edge-on.</source>
            <translation>alguns pontos de enlace não são determinados: meça cada um em pelo menos duas imagens, em um plano que não seja visto de perfil.</translation>
        </message>
        <message>
            <source>some LCP coordinates are not determined: give each a covariance.</source>
            <translation>algumas coordenadas de LCP não são determinadas: dê a cada uma uma covariância.</translation>
        </message>
        <message>
            <source>some ground point coordinates are not determined: give each sx, sy, sz.</source>
            <translation>algumas coordenadas de pontos de apoio não são determinadas: dê a cada uma sx, sy, sz.</translation>
        </message>
        <message>
            <source>INS parameters are not determined: the INS grade sigmas must be &gt; 0.</source>
            <translation>os parâmetros do INS não são determinados: os desvios-padrão da classe do INS devem ser &gt; 0.</translation>
        </message>
        <message>
            <source>parameters not observable: {names}</source>
            <translation>parâmetros não observáveis: {names}</translation>
        </message>
        <message>
            <source>the boresight of group '{group}' is not determined at all: its images have no (or too few) measurements; measure control in them, or use one boresight for all images (groups = single).</source>
            <translation>o boresight do grupo '{group}' não é determinado de forma alguma: suas imagens não têm medições (ou têm poucas demais); meça controle nelas, ou use um só boresight para todas as imagens (groups = single).</translation>
        </message>
        <message>
            <source>kappa of group '{group}' is not observable: too few points, or all of them near the image centre; measure points spread over the whole image (towards the corners) on roofs facing different directions, or add LCPs or ridge lines.</source>
            <translation>kappa do grupo '{group}' não é observável: pontos de menos, ou todos perto do centro da imagem; meça pontos distribuídos por toda a imagem (em direção aos cantos) em telhados voltados para direções diferentes, ou acrescente LCPs ou linhas de cumeeira.</translation>
        </message>
        <message>
            <source>{angles} of group '{group}' cannot be separated: the points lie near the image centre or on planes of one orientation; spread points over the image on roofs of different slope and aspect, or add LCPs or lines.</source>
            <translation>{angles} do grupo '{group}' não podem ser separados: os pontos estão perto do centro da imagem ou em planos de uma só orientação; distribua pontos pela imagem em telhados de inclinação e orientação diferentes, ou acrescente LCPs ou linhas.</translation>
        </message>
        <message>
            <source>the camera timing offset dt is correlated with {names}: its sigma ({sigma:.2f} ms) carries that trade-off (strips at different speeds, or held interior orientation and lever arm, separate them better)</source>
            <translation>o atraso de disparo da câmera dt está correlacionado com {names}: seu desvio-padrão ({sigma:.2f} ms) carrega essa troca (faixas a velocidades diferentes, ou orientação interior e braço de alavanca fixos, os separam melhor)</translation>
        </message>
        <message>
            <source>insignificant (t = {t:.2f} &lt;= {critical:.2f}, alpha {alpha:g})</source>
            <translation>não significativo (t = {t:.2f} &lt;= {critical:.2f}, alfa {alpha:g})</translation>
        </message>
        <message>
            <source>insignificant (t = {t:.2f} &lt;= {critical:.2f}, alpha {alpha:g}), also jointly with {others} (F = {f:.2f} &lt;= {fcritical:.2f})</source>
            <translation>não significativo (t = {t:.2f} &lt;= {critical:.2f}, alfa {alpha:g}), também em conjunto com {others} (F = {f:.2f} &lt;= {fcritical:.2f})</translation>
        </message>
        <message>
            <source>kept: insignificant alone (t = {t:.2f} &lt;= {critical:.2f}) but jointly significant with {others} (F = {f:.2f} &gt; {fcritical:.2f})</source>
            <translation>mantido: não significativo sozinho (t = {t:.2f} &lt;= {critical:.2f}), mas significativo em conjunto com {others} (F = {f:.2f} &gt; {fcritical:.2f})</translation>
        </message>
        <message>
            <source>significant (t = {t:.2f} &gt; {critical:.2f})</source>
            <translation>significativo (t = {t:.2f} &gt; {critical:.2f})</translation>
        </message>
        <message>
            <source>not tested (no standard deviation)</source>
            <translation>não testado (sem desvio-padrão)</translation>
        </message>
        <message>
            <source>{n} ground point(s) are not measured in any image and were not used: {ids}</source>
            <translation>{n} ponto(s) de terreno não foram medidos em nenhuma imagem e não foram usados: {ids}</translation>
        </message>
        <message>
            <source>view {view!r} left out: fewer than {minimum} target points</source>
            <translation>vista {view!r} descartada: menos de {minimum} pontos do alvo</translation>
        </message>
        <message>
            <source>{parameter} is not significant (t = {t:.2f} &lt; {critical:.2f}): consider holding it at zero</source>
            <translation>{parameter} não é significativo (t = {t:.2f} &lt; {critical:.2f}): considere fixá-lo em zero</translation>
        </message>
        <message>
            <source>resection sigma0 {sigma0:.3g} &gt; {maximum:g}</source>
            <translation>sigma0 da resseção {sigma0:.3g} &gt; {maximum:g}</translation>
        </message>
        <message>
            <source>chip from the plate photo: the plate hides the ground at the point</source>
            <translation>recorte (chip) feito da foto com a placa: a placa encobre o terreno no ponto</translation>
        </message>
        <message>
            <source>the photo sees {valid:.1f} % of the chip (&lt; {minimum:g} %)</source>
            <translation>a foto cobre {valid:.1f} % do recorte (&lt; {minimum:g} %)</translation>
        </message>
        <message>
            <source>plate resection failed: {error}</source>
            <translation>a resseção da placa falhou: {error}</translation>
        </message>
        <message>
            <source>no plate-free photo (allow the chip from the plate photo to make it anyway)</source>
            <translation>não há foto sem a placa (permita o recorte a partir da foto com a placa para gerá-lo mesmo assim)</translation>
        </message>
        <message>
            <source>too few SIFT matches: {inliers} RANSAC inliers of {matches} matches (&lt; {minimum})</source>
            <translation>poucas correspondências SIFT: {inliers} aceitas pelo RANSAC de {matches} correspondências (&lt; {minimum})</translation>
        </message>
        <message>
            <source>{n} SIFT matches rejected by data snooping</source>
            <translation>{n} correspondências SIFT rejeitadas pelo data snooping</translation>
        </message>
        <message>
            <source>plate-free photo resection failed: {error}</source>
            <translation>a resseção da foto sem a placa falhou: {error}</translation>
        </message>
        <message>
            <source>low correlation (NCC {ncc:.2f} &lt; {minimum:.2f})</source>
            <translation>correlação baixa (NCC {ncc:.2f} &lt; {minimum:.2f})</translation>
        </message>
        <message>
            <source>NCC peak on the search border</source>
            <translation>pico da NCC na borda da área de busca</translation>
        </message>
        <message>
            <source>LSM: {reason}</source>
            <translation>LSM: {reason}</translation>
        </message>
        <message>
            <source>transfer from {image}</source>
            <translation>transferência de {image}</translation>
        </message>
        <message>
            <source>{reason}; transfer from {image}: {transfer_reason}</source>
            <translation>{reason}; transferência de {image}: {transfer_reason}</translation>
        </message>
        <message>
            <source>search window outside the image</source>
            <translation>janela de busca fora da imagem</translation>
        </message>
        <message>
            <source>outside the search ellipse</source>
            <translation>fora da elipse de busca</translation>
        </message>
        <message>
            <source>chip has no-data pixels</source>
            <translation>o recorte (chip) tem pixels sem dados</translation>
        </message>
        <message>
            <source>chip refused: {why}</source>
            <translation>recorte (chip) recusado: {why}</translation>
        </message>
        <message>
            <source>outside every image</source>
            <translation>fora de todas as imagens</translation>
        </message>
        <message>
            <source>template partly outside the image</source>
            <translation>janela de referência parcialmente fora da imagem</translation>
        </message>
        <message>
            <source>plate not found: no quadrilateral in the photo</source>
            <translation>placa não encontrada: nenhum quadrilátero na foto</translation>
        </message>
        <message>
            <source>only one square: {n} quadrilateral(s), none with a nested square of the plate's inner/outer ratio</source>
            <translation>apenas um quadrado: {n} quadrilátero(s), nenhum com um quadrado interno na razão interno/externo da placa</translation>
        </message>
        <message>
            <source>ambiguous: {n} plate-like pairs of squares</source>
            <translation>ambíguo: {n} pares de quadrados semelhantes à placa</translation>
        </message>
        <message>
            <source>edge fit failed: a corner falls outside the camera's field</source>
            <translation>o ajuste da borda falhou: um canto fica fora do campo de visão da câmera</translation>
        </message>
        <message>
            <source>edge fit failed: side {side} has {n} edge points</source>
            <translation>o ajuste da borda falhou: o lado {side} tem {n} pontos de borda</translation>
        </message>
        <message>
            <source>ok</source>
            <translation>ok</translation>
        </message>
        <message>
            <source>no texture</source>
            <translation>sem textura</translation>
        </message>
        <message>
            <source>left the search window</source>
            <translation>saiu da janela de busca</translation>
        </message>
        <message>
            <source>not converged</source>
            <translation>não convergiu</translation>
        </message>
        <message>
            <source>moved too far</source>
            <translation>deslocou-se demais</translation>
        </message>
        <message>
            <source>low correlation</source>
            <translation>correlação baixa</translation>
        </message>
        <message>
            <source>sigma too large</source>
            <translation>sigma grande demais</translation>
        </message>
        <message>
            <source>no redundancy: the orientation cannot be checked</source>
            <translation>sem redundância: a orientação não pode ser verificada</translation>
        </message>
        <message>
            <source>edge only</source>
            <translation>apenas uma borda</translation>
        </message>
        <message>
            <source>weak texture</source>
            <translation>textura fraca</translation>
        </message>
        <message>
            <source>without the {n} flagged point(s)</source>
            <translation>sem o(s) {n} ponto(s) marcado(s)</translation>
        </message>
        <message>
            <source>all points</source>
            <translation>todos os pontos</translation>
        </message>
        <message>
            <source>all points (flagged included)</source>
            <translation>todos os pontos (incluindo os marcados)</translation>
        </message>
        <message>
            <source>component</source>
            <translation>componente</translation>
        </message>
        <message>
            <source>mean (m)</source>
            <translation>média (m)</translation>
        </message>
        <message>
            <source>std (m)</source>
            <translation>desvio-padrão (m)</translation>
        </message>
        <message>
            <source>min (m)</source>
            <translation>mín. (m)</translation>
        </message>
        <message>
            <source>max (m)</source>
            <translation>máx. (m)</translation>
        </message>
        <message>
            <source>PASS</source>
            <translation>APROVADO</translation>
        </message>
        <message>
            <source>FAIL</source>
            <translation>REPROVADO</translation>
        </message>
        <message>
            <source>INSUFFICIENT</source>
            <translation>INSUFICIENTE</translation>
        </message>
        <message>
            <source>INFO</source>
            <translation>INFORMATIVO</translation>
        </message>
        <message>
            <source>Statistics: standard deviation with n &amp;minus; 1; RMSE = sqrt(mean(d&amp;sup2;)); Shapiro-Wilk by scipy (Royston's algorithm); Student t two-sided for a zero mean; chi-square one-sided, (n &amp;minus; 1) s&amp;sup2; / sigma0&amp;sup2; against chi-square(1 &amp;minus; alpha, n &amp;minus; 1).</source>
            <translation>Estatísticas: desvio-padrão com n &amp;minus; 1; RMSE = sqrt(média(d&amp;sup2;)); Shapiro-Wilk pelo scipy (algoritmo de Royston); t de Student bilateral para média nula; qui-quadrado unilateral, (n &amp;minus; 1) s&amp;sup2; / sigma0&amp;sup2; contra qui-quadrado(1 &amp;minus; alfa, n &amp;minus; 1).</translation>
        </message>
        <message>
            <source>Figures marked &lt;i&gt;uncertain&lt;/i&gt; in the verdicts come from our reading of the standard or from secondary sources; check them against the official text before a contractual statement.</source>
            <translation>Os valores marcados como &lt;i&gt;incertos&lt;/i&gt; nos vereditos vêm da nossa leitura do padrão ou de fontes secundárias; confira-os com o texto oficial antes de uma declaração contratual.</translation>
        </message>
        <message>
            <source>Status INSUFFICIENT: the standard needs more check points than were given; the figures are computed but no conformance is claimed.</source>
            <translation>Estado INSUFICIENTE: o padrão exige mais pontos de verificação do que os informados; os valores são calculados, mas nenhuma conformidade é declarada.</translation>
        </message>
        <message>
            <source>decision</source>
            <translation>decisão</translation>
        </message>
        <message>
            <source>Student t</source>
            <translation>t de Student</translation>
        </message>
        <message>
            <source>t critical</source>
            <translation>t crítico</translation>
        </message>
        <message>
            <source>chi-square</source>
            <translation>qui-quadrado</translation>
        </message>
        <message>
            <source>chi-square critical</source>
            <translation>qui-quadrado crítico</translation>
        </message>
        <message>
            <source>not tested</source>
            <translation>não testado</translation>
        </message>
        <message>
            <source>value (m)</source>
            <translation>valor (m)</translation>
        </message>
        <message>
            <source>{}, used (m)</source>
            <translation>{}, usado (m)</translation>
        </message>
        <message>
            <source>Plots</source>
            <translation>Gráficos</translation>
        </message>
        <message>
            <source>Histogram of {}</source>
            <translation>Histograma de {}</translation>
        </message>
        <message>
            <source>item</source>
            <translation>item</translation>
        </message>
        <message>
            <source>value</source>
            <translation>valor</translation>
        </message>
        <message>
            <source>Summary</source>
            <translation>Resumo</translation>
        </message>
        <message>
            <source>Standards</source>
            <translation>Padrões</translation>
        </message>
        <message>
            <source>Statistics</source>
            <translation>Estatísticas</translation>
        </message>
        <message>
            <source>Outliers</source>
            <translation>Outliers</translation>
        </message>
        <message>
            <source>Check points</source>
            <translation>Pontos de verificação</translation>
        </message>
        <message>
            <source>group</source>
            <translation>grupo</translation>
        </message>
        <message>
            <source>outlier</source>
            <translation>outlier</translation>
        </message>
        <message>
            <source>used</source>
            <translation>usado</translation>
        </message>
        <message>
            <source>normal</source>
            <translation>normal</translation>
        </message>
        <message>
            <source>not normal</source>
            <translation>não normal</translation>
        </message>
        <message>
            <source>bias</source>
            <translation>tendência</translation>
        </message>
        <message>
            <source>no bias</source>
            <translation>sem tendência</translation>
        </message>
        <message>
            <source>check</source>
            <translation>verificação</translation>
        </message>
        <message>
            <source>status</source>
            <translation>estado</translation>
        </message>
        <message>
            <source>measured</source>
            <translation>medido</translation>
        </message>
        <message>
            <source>limit</source>
            <translation>limite</translation>
        </message>
        <message>
            <source>reason</source>
            <translation>motivo</translation>
        </message>
        <message>
            <source>check points</source>
            <translation>pontos de verificação</translation>
        </message>
        <message>
            <source>source</source>
            <translation>fonte</translation>
        </message>
        <message>
            <source>CRS</source>
            <translation>SRC</translation>
        </message>
        <message>
            <source>sign convention</source>
            <translation>convenção de sinal</translation>
        </message>
        <message>
            <source>d = measured &amp;minus; reference, metres</source>
            <translation>d = medido &amp;minus; referência, metros</translation>
        </message>
        <message>
            <source>significance level</source>
            <translation>nível de significância</translation>
        </message>
        <message>
            <source>created</source>
            <translation>criado</translation>
        </message>
        <message>
            <source>No standard was selected.</source>
            <translation>Nenhum padrão foi selecionado.</translation>
        </message>
        <message>
            <source>Project threshold per group</source>
            <translation>Limiar do projeto por grupo</translation>
        </message>
        <message>
            <source>No point flagged.</source>
            <translation>Nenhum ponto marcado.</translation>
        </message>
        <message>
            <source>yes</source>
            <translation>sim</translation>
        </message>
        <message>
            <source>no</source>
            <translation>não</translation>
        </message>
        <message>
            <source>Notes</source>
            <translation>Notas</translation>
        </message>
        <message>
            <source>Source: {}. {} check points.</source>
            <translation>Fonte: {}. {} pontos de verificação.</translation>
        </message>
        <message>
            <source>Normal Q-Q plot of {}</source>
            <translation>Gráfico Q-Q normal de {}</translation>
        </message>
        <message>
            <source>{} ({} in the statistics)</source>
            <translation>{} ({} nas estatísticas)</translation>
        </message>
        <message>
            <source>not stated</source>
            <translation>não informado</translation>
        </message>
        <message>
            <source>For comparison: {} ({})</source>
            <translation>Para comparação: {} ({})</translation>
        </message>
        <message>
            <source>Group {} ({})</source>
            <translation>Grupo {} ({})</translation>
        </message>
        <message>
            <source>; excluded from the statistics and the standards.</source>
            <translation>; excluídos das estatísticas e dos padrões.</translation>
        </message>
        <message>
            <source>; kept in the statistics (not excluded).</source>
            <translation>; mantidos nas estatísticas (não excluídos).</translation>
        </message>
        <message>
            <source>accepted</source>
            <translation>aceito</translation>
        </message>
        <message>
            <source>rejected</source>
            <translation>rejeitado</translation>
        </message>
        <message>
            <source>Rule: {}.</source>
            <translation>Regra: {}.</translation>
        </message>
        <message>
            <source>{} point(s) flagged: </source>
            <translation>{} ponto(s) marcado(s): </translation>
        </message>
        <message>
            <source>Positional accuracy report</source>
            <translation>Relatório de acurácia posicional</translation>
        </message>
        <message>
            <source>perspective centre</source>
            <translation>centro perspectivo</translation>
        </message>
        <message>
            <source>control point</source>
            <translation>ponto de controle</translation>
        </message>
        <message>
            <source>check point</source>
            <translation>ponto de verificação</translation>
        </message>
        <message>
            <source>tie point</source>
            <translation>ponto de ligação</translation>
        </message>
        <message>
            <source>images covering</source>
            <translation>imagens que cobrem</translation>
        </message>
        <message>
            <source>{} m on the ground</source>
            <translation>{} m no terreno</translation>
        </message>
        <message>
            <source>parameter</source>
            <translation>parâmetro</translation>
        </message>
        <message>
            <source>value (ms)</source>
            <translation>valor (ms)</translation>
        </message>
        <message>
            <source>sigma (ms)</source>
            <translation>desvio-padrão (ms)</translation>
        </message>
        <message>
            <source>The calibration FAILED its checks: no table and no exterior orientation were written. The numbers below show the failed adjustment, for diagnosis only.</source>
            <translation>A calibração FALHOU nas verificações: nenhuma tabela e nenhuma orientação exterior foram gravadas. Os números abaixo mostram o ajustamento que falhou, apenas para diagnóstico.</translation>
        </message>
        <message>
            <source>axis</source>
            <translation>eixo</translation>
        </message>
        <message>
            <source>sigma (m)</source>
            <translation>sigma (m)</translation>
        </message>
        <message>
            <source>value (mm)</source>
            <translation>valor (mm)</translation>
        </message>
        <message>
            <source>sigma (mm)</source>
            <translation>sigma (mm)</translation>
        </message>
        <message>
            <source>Boresight calibration</source>
            <translation>Calibração de boresight</translation>
        </message>
        <message>
            <source>Angles: d_omega, d_phi, d_kappa about the camera axes x, y, z (R_c^b = R_nominal dR); standard deviations are a-posteriori (scaled by sigma0) unless labelled a-priori.</source>
            <translation>Ângulos: d_omega, d_phi, d_kappa em torno dos eixos x, y, z da câmera (R_c^b = R_nominal dR); os desvios-padrão são a posteriori (escalados por sigma0), salvo quando indicados como a priori.</translation>
        </message>
        <message>
            <source>Settings</source>
            <translation>Configurações</translation>
        </message>
        <message>
            <source>setting</source>
            <translation>configuração</translation>
        </message>
        <message>
            <source>Camera timing offset</source>
            <translation>Atraso de disparo da câmera</translation>
        </message>
        <message>
            <source>exposure = recorded time + dt</source>
            <translation>exposição = tempo registrado + dt</translation>
        </message>
        <message>
            <source>correlation with dt</source>
            <translation>correlação com dt</translation>
        </message>
        <message>
            <source>Boresight</source>
            <translation>Boresight</translation>
        </message>
        <message>
            <source>angle</source>
            <translation>ângulo</translation>
        </message>
        <message>
            <source>value (deg)</source>
            <translation>valor (graus)</translation>
        </message>
        <message>
            <source>value (d m s)</source>
            <translation>valor (g m s)</translation>
        </message>
        <message>
            <source>value (arcsec)</source>
            <translation>valor (segundos de arco)</translation>
        </message>
        <message>
            <source>sigma (arcsec)</source>
            <translation>sigma (segundos de arco)</translation>
        </message>
        <message>
            <source>sigma a-priori (arcsec)</source>
            <translation>sigma a priori (segundos de arco)</translation>
        </message>
        <message>
            <source>Adjustment</source>
            <translation>Ajustamento</translation>
        </message>
        <message>
            <source>figure</source>
            <translation>grandeza</translation>
        </message>
        <message>
            <source>Correlation of the calibration parameters</source>
            <translation>Correlação dos parâmetros de calibração</translation>
        </message>
        <message>
            <source>Rejected observations</source>
            <translation>Observações rejeitadas</translation>
        </message>
        <message>
            <source>Not observable</source>
            <translation>Não observável</translation>
        </message>
        <message>
            <source>The calibration was not computed:</source>
            <translation>A calibração não foi calculada:</translation>
        </message>
        <message>
            <source>Lever arm (body frame)</source>
            <translation>Braço de alavanca (referencial do corpo)</translation>
        </message>
        <message>
            <source>Interior orientation</source>
            <translation>Orientação interior</translation>
        </message>
        <message>
            <source>sigma0 (a-posteriori, a-priori 1)</source>
            <translation>sigma0 (a posteriori, a priori 1)</translation>
        </message>
        <message>
            <source>redundancy</source>
            <translation>redundância</translation>
        </message>
        <message>
            <source>observations / constraints</source>
            <translation>observações / injunções</translation>
        </message>
        <message>
            <source>global chi-square statistic</source>
            <translation>estatística qui-quadrado global</translation>
        </message>
        <message>
            <source>p-value</source>
            <translation>valor p</translation>
        </message>
        <message>
            <source>global test</source>
            <translation>teste global</translation>
        </message>
        <message>
            <source>iterations</source>
            <translation>iterações</translation>
        </message>
        <message>
            <source>outlier detection</source>
            <translation>detecção de outliers</translation>
        </message>
        <message>
            <source>image</source>
            <translation>imagem</translation>
        </message>
        <message>
            <source>point</source>
            <translation>ponto</translation>
        </message>
        <message>
            <source>type</source>
            <translation>tipo</translation>
        </message>
        <message>
            <source>target</source>
            <translation>alvo</translation>
        </message>
        <message>
            <source>None.</source>
            <translation>Nenhuma.</translation>
        </message>
        <message>
            <source>Image residuals</source>
            <translation>Resíduos das imagens</translation>
        </message>
        <message>
            <source>Residual vx</source>
            <translation>Resíduo vx</translation>
        </message>
        <message>
            <source>col residual (px)</source>
            <translation>resíduo em coluna (px)</translation>
        </message>
        <message>
            <source>Residual vy</source>
            <translation>Resíduo vy</translation>
        </message>
        <message>
            <source>row residual (px)</source>
            <translation>resíduo em linha (px)</translation>
        </message>
        <message>
            <source>passed</source>
            <translation>aprovado</translation>
        </message>
        <message>
            <source>failed</source>
            <translation>reprovado</translation>
        </message>
        <message>
            <source>Warnings</source>
            <translation>Avisos</translation>
        </message>
        <message>
            <source>acceptance interval (alpha = {})</source>
            <translation>intervalo de aceitação (alfa = {})</translation>
        </message>
        <message>
            <source>{} (converged: {})</source>
            <translation>{} (convergiu: {})</translation>
        </message>
        <message>
            <source>{} image points kept: RMS residual {} px (col), {} px (row).</source>
            <translation>{} pontos de imagem mantidos: resíduo RMS {} px (coluna), {} px (linha).</translation>
        </message>
        <message>
            <source>rank</source>
            <translation>posição</translation>
        </message>
        <message>
            <source>AP model</source>
            <translation>modelo de PAs</translation>
        </message>
        <message>
            <source>mean horizontal (m)</source>
            <translation>média horizontal (m)</translation>
        </message>
        <message>
            <source>std horizontal (m)</source>
            <translation>desvio-padrão horizontal (m)</translation>
        </message>
        <message>
            <source>APs</source>
            <translation>PAs</translation>
        </message>
        <message>
            <source>APs kept</source>
            <translation>PAs mantidos</translation>
        </message>
        <message>
            <source>significant</source>
            <translation>significativo</translation>
        </message>
        <message>
            <source>FAILED</source>
            <translation>REPROVADO</translation>
        </message>
        <message>
            <source>passed, but only after more rejections than false alarms explain</source>
            <translation>aprovado, mas só depois de mais rejeições do que os falsos alarmes explicam</translation>
        </message>
        <message>
            <source>estimated</source>
            <translation>estimado</translation>
        </message>
        <message>
            <source>dropped</source>
            <translation>descartado</translation>
        </message>
        <message>
            <source>fixed</source>
            <translation>fixo</translation>
        </message>
        <message>
            <source>camera</source>
            <translation>câmera</translation>
        </message>
        <message>
            <source>std</source>
            <translation>desvio-padrão</translation>
        </message>
        <message>
            <source>converged</source>
            <translation>convergiu</translation>
        </message>
        <message>
            <source>sigma0 a posteriori</source>
            <translation>sigma0 a posteriori</translation>
        </message>
        <message>
            <source>global chi-square test</source>
            <translation>teste qui-quadrado global</translation>
        </message>
        <message>
            <source>outliers</source>
            <translation>outliers</translation>
        </message>
        <message>
            <source>condition number (reduced system)</source>
            <translation>número de condição (sistema reduzido)</translation>
        </message>
        <message>
            <source>details</source>
            <translation>detalhes</translation>
        </message>
        <message>
            <source>Image overlap, control and check points</source>
            <translation>Sobreposição das imagens, pontos de controle e de verificação</translation>
        </message>
        <message>
            <source>Camera timing offset (exposure = recorded time + dt)</source>
            <translation>Atraso de disparo da câmera (exposição = tempo registrado + dt)</translation>
        </message>
        <message>
            <source>NO</source>
            <translation>NÃO</translation>
        </message>
        <message>
            <source>no redundancy</source>
            <translation>sem redundância</translation>
        </message>
        <message>
            <source>significant ({})</source>
            <translation>significativo ({})</translation>
        </message>
        <message>
            <source>Block map</source>
            <translation>Mapa do bloco</translation>
        </message>
        <message>
            <source>Lens distortion</source>
            <translation>Distorção da lente</translation>
        </message>
        <message>
            <source>mapping CRS and units in the settings; image residuals in pixels (adjusted minus measured).</source>
            <translation>SRC de mapeamento e unidades nas configurações; resíduos das imagens em pixels (ajustado menos medido).</translation>
        </message>
        <message>
            <source>Interior orientation and additional parameters</source>
            <translation>Orientação interior e parâmetros adicionais</translation>
        </message>
        <message>
            <source>Images</source>
            <translation>Imagens</translation>
        </message>
        <message>
            <source>points used</source>
            <translation>pontos usados</translation>
        </message>
        <message>
            <source>RMS col (px)</source>
            <translation>RMS col (px)</translation>
        </message>
        <message>
            <source>RMS row (px)</source>
            <translation>RMS lin (px)</translation>
        </message>
        <message>
            <source>Rejected measurements ({})</source>
            <translation>Medições rejeitadas ({})</translation>
        </message>
        <message>
            <source>Scale bars</source>
            <translation>Barras de escala</translation>
        </message>
        <message>
            <source>bar</source>
            <translation>barra</translation>
        </message>
        <message>
            <source>distance (m)</source>
            <translation>distância (m)</translation>
        </message>
        <message>
            <source>adjusted (m)</source>
            <translation>ajustada (m)</translation>
        </message>
        <message>
            <source>adjusted sigma (m)</source>
            <translation>sigma ajustado (m)</translation>
        </message>
        <message>
            <source>v (m)</source>
            <translation>v (m)</translation>
        </message>
        <message>
            <source>after {} iterations</source>
            <translation>após {} iterações</translation>
        </message>
        <message>
            <source>a priori {}</source>
            <translation>a priori {}</translation>
        </message>
        <message>
            <source>{} observation rows, {} parameters, {} constraint rows</source>
            <translation>{} linhas de observação, {} parâmetros, {} linhas de injunção</translation>
        </message>
        <message>
            <source>AP models compared (check-point discrepancies)</source>
            <translation>Modelos de PAs comparados (discrepâncias nos pontos de verificação)</translation>
        </message>
        <message>
            <source>Planimetric discrepancy = horizontal distance between the intersected and the surveyed check point; ranked by the 3D RMS (sigma0 without check points). The outputs are those of the best model (highlighted).</source>
            <translation>Discrepância planimétrica = distância horizontal entre o ponto de verificação intersectado e o levantado; ordenados pelo RMS 3D (sigma0 sem pontos de verificação). As saídas são as do melhor modelo (destacado).</translation>
        </message>
        <message>
            <source>Lever arm and boresight corrections (camera axes)</source>
            <translation>Correções do braço de alavanca e do boresight (eixos da câmera)</translation>
        </message>
        <message>
            <source>Check points (not in the adjustment)</source>
            <translation>Pontos de verificação (fora do ajustamento)</translation>
        </message>
        <message>
            <source>images</source>
            <translation>imagens</translation>
        </message>
        <message>
            <source>v col</source>
            <translation>v col</translation>
        </message>
        <message>
            <source>residual (px)</source>
            <translation>resíduo (px)</translation>
        </message>
        <message>
            <source>v row</source>
            <translation>v lin</translation>
        </message>
        <message>
            <source>Residuals</source>
            <translation>Resíduos</translation>
        </message>
        <message>
            <source>w col</source>
            <translation>w col</translation>
        </message>
        <message>
            <source>w row</source>
            <translation>w lin</translation>
        </message>
        <message>
            <source>statistic {}, accepted [{}, {}], p = {}</source>
            <translation>estatística {}, aceita em [{}, {}], p = {}</translation>
        </message>
        <message>
            <source>rejections explained by false alarms</source>
            <translation>rejeições explicadas por falsos alarmes</translation>
        </message>
        <message>
            <source>Bundle adjustment: {}</source>
            <translation>Ajustamento por feixes de raios: {}</translation>
        </message>
        <message>
            <source>Bundle adjustment with self-calibration ({})</source>
            <translation>Ajustamento por feixes de raios com autocalibração ({})</translation>
        </message>
        <message>
            <source>Dropped by the selection, in order: </source>
            <translation>Descartados pela seleção, em ordem: </translation>
        </message>
        <message>
            <source>lever dx (m)</source>
            <translation>braço dx (m)</translation>
        </message>
        <message>
            <source>lever dy (m)</source>
            <translation>braço dy (m)</translation>
        </message>
        <message>
            <source>lever dz (m)</source>
            <translation>braço dz (m)</translation>
        </message>
        <message>
            <source>boresight d_omega (deg)</source>
            <translation>boresight d_omega (graus)</translation>
        </message>
        <message>
            <source>boresight d_phi (deg)</source>
            <translation>boresight d_phi (graus)</translation>
        </message>
        <message>
            <source>boresight d_kappa (deg)</source>
            <translation>boresight d_kappa (graus)</translation>
        </message>
        <message>
            <source>correlated with dt</source>
            <translation>correlacionado com dt</translation>
        </message>
        <message>
            <source>Horizontal discrepancy: mean {} m, standard deviation {} m, RMSE_HORIZONTAL {} m; RMSE_E / RMSE_N / RMSE_U {} / {} / {} m; RMSE_3D {} m. Intersected with the adjusted orientations; their sigmas carry the image noise only.</source>
            <translation>Discrepância horizontal: média {} m, desvio-padrão {} m, RMSE_HORIZONTAL {} m; RMSE_E / RMSE_N / RMSE_U {} / {} / {} m; RMSE_3D {} m. Interseção com as orientações ajustadas; os seus sigmas refletem apenas o ruído das imagens.</translation>
        </message>
        <message>
            <source>not observable: {}</source>
            <translation>não observável: {}</translation>
        </message>
        <message>
            <source>Lens correction: {}</source>
            <translation>Correção da lente: {}</translation>
        </message>
        <message>
            <source>Radial profile: {}</source>
            <translation>Perfil radial: {}</translation>
        </message>
        <message>
            <source>|correlation| above {} in the final adjustment: </source>
            <translation>|correlação| acima de {} no ajustamento final: </translation>
        </message>
        <message>
            <source>Correlations: {}</source>
            <translation>Correlações: {}</translation>
        </message>
        <message>
            <source>Image residuals: {}</source>
            <translation>Resíduos das imagens: {}</translation>
        </message>
        <message>
            <source>view</source>
            <translation>vista</translation>
        </message>
        <message>
            <source>points</source>
            <translation>pontos</translation>
        </message>
        <message>
            <source>Camera calibration</source>
            <translation>Calibração de câmera</translation>
        </message>
        <message>
            <source>Standard deviations a-posteriori (scaled by sigma0). Lens coefficients: Brown-Conrady correction of measured coordinates in mm (ideal = measured + d); t = |value| / sigma against Student's t (two-sided 5 %, the redundancy as degrees of freedom).</source>
            <translation>Desvios-padrão a posteriori (escalados por sigma0). Coeficientes da lente: correção de Brown-Conrady das coordenadas medidas em mm (ideal = medida + d); t = |valor| / sigma comparado com o t de Student (bilateral 5 %, a redundância como graus de liberdade).</translation>
        </message>
        <message>
            <source>not significant</source>
            <translation>não significativo</translation>
        </message>
        <message>
            <source>test</source>
            <translation>teste</translation>
        </message>
        <message>
            <source>Correlations</source>
            <translation>Correlações</translation>
        </message>
        <message>
            <source>Views</source>
            <translation>Vistas</translation>
        </message>
        <message>
            <source>Camera calibration: {} ({})</source>
            <translation>Calibração de câmera: {} ({})</translation>
        </message>
        <message>
            <source>f = {} px, principal point ({}, {}) px; RMS {} px over {} points; sigma0 {} (a-priori {} px), redundancy {}, global test {}.</source>
            <translation>f = {} px, ponto principal ({}, {}) px; RMS {} px em {} pontos; sigma0 {} (a priori {} px), redundância {}, teste global {}.</translation>
        </message>
        <message>
            <source>outside</source>
            <translation>fora</translation>
        </message>
        <message>
            <source>chip</source>
            <translation>recorte (chip)</translation>
        </message>
        <message>
            <source>Control point location</source>
            <translation>Localização de pontos de controle</translation>
        </message>
        <message>
            <source>NCC with an adaptive template, then least-squares matching (Gruen 1985: 6 affine + 2 radiometric parameters). Pixels: corner convention (centre of the first pixel at 0.5, 0.5); sigmas a posteriori from LSM (they do not include the chip's own errors).</source>
            <translation>NCC com janela de referência adaptativa, seguida de correspondência por mínimos quadrados (Gruen 1985: 6 parâmetros afins + 2 radiométricos). Pixels: convenção de canto (centro do primeiro pixel em 0,5, 0,5); sigmas a posteriori da LSM (não incluem os erros do próprio recorte (chip)).</translation>
        </message>
        <message>
            <source>pairs</source>
            <translation>pares</translation>
        </message>
        <message>
            <source>Points and images</source>
            <translation>Pontos e imagens</translation>
        </message>
        <message>
            <source>row</source>
            <translation>lin</translation>
        </message>
        <message>
            <source>sigma row</source>
            <translation>sigma lin</translation>
        </message>
        <message>
            <source>LSM corr.</source>
            <translation>corr. LSM</translation>
        </message>
        <message>
            <source>template px</source>
            <translation>janela de referência (px)</translation>
        </message>
        <message>
            <source>Chip gallery</source>
            <translation>Galeria de recortes (chips)</translation>
        </message>
        <message>
            <source>Left: the chip in the image geometry; right: the image at the match.</source>
            <translation>À esquerda: o recorte (chip) na geometria da imagem; à direita: a imagem no local da correspondência.</translation>
        </message>
        <message>
            <source>{} in {}: {}</source>
            <translation>{} em {}: {}</translation>
        </message>
        <message>
            <source>These results FAILED their checks and were written only because the user asked for them (ACCEPT_DOUBTFUL): do not use them without review.</source>
            <translation>Estes resultados FALHARAM nas verificações e foram gravados apenas porque o usuário os pediu (ACCEPT_DOUBTFUL): não os use sem revisão.</translation>
        </message>
        <message>
            <source>at most {bound} ({expected} expected); {k} rejected: P = {p}</source>
            <translation>no máximo {bound} ({expected} esperadas); {k} rejeitadas: P = {p}</translation>
        </message>
        <message>
            <source>distance from the principal point (px)</source>
            <translation>distância ao ponto principal (px)</translation>
        </message>
        <message>
            <source>correction (px)</source>
            <translation>correção (px)</translation>
        </message>
        <message>
            <source>tangential</source>
            <translation>tangencial</translation>
        </message>
        <message>
            <source>correction (measured to ideal); {} px = {} px on screen; {} px at the corners</source>
            <translation>correção (medida para ideal); {} px = {} px na tela; {} px nos cantos</translation>
        </message>
        <message>
            <source>radial</source>
            <translation>radial</translation>
        </message>
        <message>
            <source>control points: RMS |v| (px)</source>
            <translation>pontos de controle: RMS |v| (px)</translation>
        </message>
        <message>
            <source>line points: RMS distance from the projected line (px)</source>
            <translation>pontos de linha: RMS da distância à linha projetada (px)</translation>
        </message>
        <message>
            <source>check points: RMS |projected - measured| (px)</source>
            <translation>pontos de verificação: RMS |projetado - medido| (px)</translation>
        </message>
        <message>
            <source>Space resection</source>
            <translation>Resseção espacial</translation>
        </message>
        <message>
            <source>Position in the mapping CRS, omega-phi-kappa relative to the grid frame at the perspective centre; standard deviations a-posteriori (scaled by sigma0) unless labelled a-priori. Global test: v'Pv / sigma0_prior^2 against the chi-square critical value (one-sided 5 %, as dos Santos et al. 2010 report it) and the two-sided acceptance range.</source>
            <translation>Posição no SRC de mapeamento, omega-phi-kappa relativos ao referencial da quadrícula no centro perspectivo; desvios-padrão a posteriori (escalados por sigma0), salvo quando indicados como a priori. Teste global: v'Pv / sigma0_prior^2 contra o valor crítico do qui-quadrado (unilateral 5 %, como dos Santos et al. 2010 o relatam) e o intervalo de aceitação bilateral.</translation>
        </message>
        <message>
            <source>lines</source>
            <translation>linhas</translation>
        </message>
        <message>
            <source>unit</source>
            <translation>unidade</translation>
        </message>
        <message>
            <source>std a-priori</source>
            <translation>desvio-padrão a priori</translation>
        </message>
        <message>
            <source>std (arcsec)</source>
            <translation>desvio-padrão (segundos de arco)</translation>
        </message>
        <message>
            <source>Global test</source>
            <translation>Teste global</translation>
        </message>
        <message>
            <source>quantity</source>
            <translation>grandeza</translation>
        </message>
        <message>
            <source>Correlation of the six parameters</source>
            <translation>Correlação dos seis parâmetros</translation>
        </message>
        <message>
            <source>what</source>
            <translation>o quê</translation>
        </message>
        <message>
            <source>count</source>
            <translation>quantidade</translation>
        </message>
        <message>
            <source>Interior orientation (refined)</source>
            <translation>Orientação interior (refinada)</translation>
        </message>
        <message>
            <source>std (mm)</source>
            <translation>desvio-padrão (mm)</translation>
        </message>
        <message>
            <source>observations (condition rows)</source>
            <translation>observações (linhas de condição)</translation>
        </message>
        <message>
            <source>sigma0 a-posteriori</source>
            <translation>sigma0 a posteriori</translation>
        </message>
        <message>
            <source>chi-square statistic v'Pv / sigma0_prior^2</source>
            <translation>estatística qui-quadrado v'Pv / sigma0_prior^2</translation>
        </message>
        <message>
            <source>critical value, one-sided 5 % (as the source)</source>
            <translation>valor crítico, unilateral 5 % (como na fonte)</translation>
        </message>
        <message>
            <source>two-sided acceptance range</source>
            <translation>intervalo de aceitação bilateral</translation>
        </message>
        <message>
            <source>verdict (one-sided)</source>
            <translation>veredito (unilateral)</translation>
        </message>
        <message>
            <source>condition number (scaled normal matrix)</source>
            <translation>número de condição (matriz normal escalada)</translation>
        </message>
        <message>
            <source>Rejected by data snooping</source>
            <translation>Rejeitados pelo data snooping</translation>
        </message>
        <message>
            <source>block</source>
            <translation>bloco</translation>
        </message>
        <message>
            <source>Image {}</source>
            <translation>Imagem {}</translation>
        </message>
        <message>
            <source>Start: {}; line model: {}; {} iterations; {} control points, {} lines, {} check points, {} rows without control ignored.</source>
            <translation>Início: {}; modelo de linha: {}; {} iterações; {} pontos de controle, {} linhas, {} pontos de verificação, {} linhas sem controle ignoradas.</translation>
        </message>
        <message>
            <source>Check-point count</source>
            <translation>Número de pontos de verificação</translation>
        </message>
        <message>
            <source>{symbol} = {value:.2f} cm: meets any class of at least {value:.2f} cm{example}{few}</source>
            <translation>{symbol} = {value:.2f} cm: atende a qualquer classe de pelo menos {value:.2f} cm{example}{few}</translation>
        </message>
        <message>
            <source>{symbol} = {value:.2f} cm {relation} {target:g} cm{few}</source>
            <translation>{symbol} = {value:.2f} cm {relation} {target:g} cm{few}</translation>
        </message>
        <message>
            <source>{axis} class {target:g}-cm</source>
            <translation>Classe {axis} de {target:g} cm</translation>
        </message>
        <message>
            <source>{axis} class</source>
            <translation>Classe {axis}</translation>
        </message>
        <message>
            <source>; only {n} of {minimum} check points</source>
            <translation>; apenas {n} de {minimum} pontos de verificação</translation>
        </message>
        <message>
            <source>Accuracy is stated as RMSE; Edition 2 no longer uses 95 % confidence figures.</source>
            <translation>A acurácia é expressa como RMSE; a Edição 2 não usa mais valores com 95 % de confiança.</translation>
        </message>
        <message>
            <source>Check-point survey error included: RMSE_HORIZONTAL_SURVEY (ASPRS RMSE_H2) = {horizontal:.2f} cm, RMSE_U_SURVEY (ASPRS RMSE_V2) = {vertical:.2f} cm (0 when not given: then the totals are RMSE_HORIZONTAL and RMSE_U of the check points alone).</source>
            <translation>Erro do levantamento dos pontos de verificação incluído: RMSE_HORIZONTAL_SURVEY (ASPRS RMSE_H2) = {horizontal:.2f} cm, RMSE_U_SURVEY (ASPRS RMSE_V2) = {vertical:.2f} cm (0 quando não informado: então os totais são o RMSE_HORIZONTAL e o RMSE_U apenas dos pontos de verificação).</translation>
        </message>
        <message>
            <source>{n} check points; Edition 2 requires at least {minimum} (and up to {maximum} for large projects)</source>
            <translation>{n} pontos de verificação; a Edição 2 exige pelo menos {minimum} (e até {maximum} para projetos grandes)</translation>
        </message>
        <message>
            <source>Horizontal</source>
            <translation>horizontal</translation>
        </message>
        <message>
            <source>Vertical (NVA)</source>
            <translation>vertical (NVA)</translation>
        </message>
        <message>
            <source>Three-dimensional accuracy</source>
            <translation>Acurácia tridimensional</translation>
        </message>
        <message>
            <source>RMSE_3D_TOTAL = sqrt(RMSE_HORIZONTAL_TOTAL^2 + RMSE_U_TOTAL^2) = {value:.2f} cm (reported, no class)</source>
            <translation>RMSE_3D_TOTAL = sqrt(RMSE_HORIZONTAL_TOTAL^2 + RMSE_U_TOTAL^2) = {value:.2f} cm (informado, sem classe)</translation>
        </message>
        <message>
            <source>ASPRS Positional Accuracy Standards, Edition 2 (2023)</source>
            <translation>Padrões de Acurácia Posicional da ASPRS, Edição 2 (2023)</translation>
        </message>
        <message>
            <source>horizontal</source>
            <translation>horizontal</translation>
        </message>
        <message>
            <source>vertical</source>
            <translation>vertical</translation>
        </message>
        <message>
            <source>; tightest example class met: {best:g}-cm</source>
            <translation>; classe de exemplo mais restrita atendida: {best:g} cm</translation>
        </message>
        <message>
            <source>The {axis} check-point survey ({survey:.2f} cm) is not at least twice as accurate as the {target:g}-cm class (uncertain reading of Ed. 2).</source>
            <translation>O levantamento {axis} dos pontos de verificação ({survey:.2f} cm) não é pelo menos duas vezes mais acurado que a classe de {target:g} cm (leitura incerta da Ed. 2).</translation>
        </message>
        <message>
            <source>The {axis} mean error ({mean:.2f} cm) exceeds 25 % of the {target:g}-cm class: investigate a systematic error (Ed. 1 section 7.4; kept as guidance in Ed. 2, uncertain).</source>
            <translation>O erro médio {axis} ({mean:.2f} cm) excede 25 % da classe de {target:g} cm: investigue um erro sistemático (Ed. 1, seção 7.4; mantido como orientação na Ed. 2, incerto).</translation>
        </message>
        <message>
            <source> (only {n} of {minimum} check points)</source>
            <translation> (apenas {n} de {minimum} pontos de verificação)</translation>
        </message>
        <message>
            <source>{n} check points; NSSDA requires at least {minimum}</source>
            <translation>{n} pontos de verificação; o NSSDA exige pelo menos {minimum}</translation>
        </message>
        <message>
            <source>Horizontal approximation condition</source>
            <translation>Condição da aproximação horizontal</translation>
        </message>
        <message>
            <source>Horizontal accuracy (95 %)</source>
            <translation>Acurácia horizontal (95 %)</translation>
        </message>
        <message>
            <source>Tested {value:.3f} m horizontal accuracy at 95 % confidence level{few}</source>
            <translation>Acurácia horizontal testada de {value:.3f} m ao nível de confiança de 95 %{few}</translation>
        </message>
        <message>
            <source>Vertical accuracy (95 %)</source>
            <translation>Acurácia vertical (95 %)</translation>
        </message>
        <message>
            <source>Tested {value:.3f} m vertical accuracy at 95 % confidence level{few}</source>
            <translation>Acurácia vertical testada de {value:.3f} m ao nível de confiança de 95 %{few}</translation>
        </message>
        <message>
            <source>Assumption: normal distribution (Shapiro-Wilk)</source>
            <translation>Hipótese: distribuição normal (Shapiro-Wilk)</translation>
        </message>
        <message>
            <source>Assumption: no systematic error (Student t)</source>
            <translation>Hipótese: ausência de erro sistemático (t de Student)</translation>
        </message>
        <message>
            <source>rejected for {components}</source>
            <translation>rejeitada para {components}</translation>
        </message>
        <message>
            <source>RMSE_min/RMSE_max = {ratio:.3f} &gt;= 0.6: Accuracy_r = 2.4477 x 0.5 (RMSE_x + RMSE_y)</source>
            <translation>RMSE_min/RMSE_max = {ratio:.3f} &gt;= 0,6: Accuracy_r = 2,4477 x 0,5 (RMSE_x + RMSE_y)</translation>
        </message>
        <message>
            <source>RMSE_min/RMSE_max = {ratio:.3f} &lt; 0.6: the NSSDA approximation does not hold; exact 95 % radius used</source>
            <translation>RMSE_min/RMSE_max = {ratio:.3f} &lt; 0,6: a aproximação do NSSDA não vale; usado o raio exato de 95 %</translation>
        </message>
        <message>
            <source>Accuracy_r = 1.7308 RMSE_r holds for RMSE_x = RMSE_y; the Case 2 formula 2.4477 x 0.5 (RMSE_x + RMSE_y) is used for 0.6 &lt;= ratio &lt;= 1; the exact 95 % radius of the bivariate normal is also given.</source>
            <translation>Accuracy_r = 1,7308 RMSE_r vale para RMSE_x = RMSE_y; a fórmula do Caso 2, 2,4477 x 0,5 (RMSE_x + RMSE_y), é usada para 0,6 &lt;= razão &lt;= 1; o raio exato de 95 % da normal bivariada também é apresentado.</translation>
        </message>
        <message>
            <source>not testable for {components}</source>
            <translation>não testável para {components}</translation>
        </message>
        <message>
            <source>accepted for E, N, H</source>
            <translation>aceita para E, N, H</translation>
        </message>
        <message>
            <source>{share:.1f} % of {n} points within PEC {pec:.3f} m ({share_relation} 90 %); RMS {rms:.3f} m {rms_relation} EP {ep:.3f} m</source>
            <translation>{share:.1f} % de {n} pontos dentro do PEC de {pec:.3f} m ({share_relation} 90 %); RMS {rms:.3f} m {rms_relation} EP {ep:.3f} m</translation>
        </message>
        <message>
            <source>none</source>
            <translation>nenhuma</translation>
        </message>
        <message>
            <source>Scale 1:{scale:,.0f}; equidistance {equidistance}. Best class met: planimetric {planimetric}, altimetric {altimetric}.</source>
            <translation>Escala 1:{scale:,.0f}; equidistância {equidistance}. Melhor classe atendida: planimétrica {planimetric}, altimétrica {altimetric}.</translation>
        </message>
        <message>
            <source>PEC-PCD limits: planimetric A-D 0.28/0.5/0.8/1.0 mm (EP 0.17/0.3/0.5/0.6 mm) at the map scale; altimetric A-D 0.27/0.50/0.60/0.75 of the equidistance (EP 1/6, 1/3, 2/5, 1/2).</source>
            <translation>Limites do PEC-PCD: planimétrico A-D 0,28/0,5/0,8/1,0 mm (EP 0,17/0,3/0,5/0,6 mm) na escala da carta; altimétrico A-D 0,27/0,50/0,60/0,75 da equidistância (EP 1/6, 1/3, 2/5, 1/2).</translation>
        </message>
        <message>
            <source>{n} check points; fewer than {minimum} makes the 90 % rule weak (common practice, not in the Decreto)</source>
            <translation>{n} pontos de verificação; menos de {minimum} torna fraca a regra dos 90 % (prática usual, não consta do Decreto)</translation>
        </message>
        <message>
            <source>PEC-PCD (Decreto 89.817 / ET-CQDG), 1:{scale:,.0f}</source>
            <translation>PEC-PCD (Decreto 89.817 / ET-CQDG), 1:{scale:,.0f}</translation>
        </message>
        <message>
            <source>Class {cls} planimetric</source>
            <translation>Classe {cls} planimétrica</translation>
        </message>
        <message>
            <source>Class {cls} altimetric</source>
            <translation>Classe {cls} altimétrica</translation>
        </message>
        <message>
            <source>Declared class {cls} (planimetric)</source>
            <translation>Classe declarada {cls} (planimétrica)</translation>
        </message>
        <message>
            <source>Declared class {cls} (altimetric)</source>
            <translation>Classe declarada {cls} (altimétrica)</translation>
        </message>
        <message>
            <source>{value:g} m</source>
            <translation>{value:g} m</translation>
        </message>
        <message>
            <source>not given</source>
            <translation>não informada</translation>
        </message>
        <message>
            <source>no equidistance given for this scale</source>
            <translation>nenhuma equidistância informada para esta escala</translation>
        </message>
        <message>
            <source>given</source>
            <translation>informado</translation>
        </message>
        <message>
            <source>Eq. 18 with H {height:g} m, B {base:g} m, f {focal:g} mm, sigma_pix {pixel:g} um</source>
            <translation>Eq. 18 com H {height:g} m, B {base:g} m, f {focal:g} mm, sigma_pix {pixel:g} µm</translation>
        </message>
        <message>
            <source>Planimetric RMSE</source>
            <translation>RMSE planimétrico</translation>
        </message>
        <message>
            <source>RMSE {rmse:.3f} m {relation} {limit:.3f} m; {beyond} of {n} points beyond it</source>
            <translation>RMSE {rmse:.3f} m {relation} {limit:.3f} m; {beyond} de {n} pontos além do limiar</translation>
        </message>
        <message>
            <source>Vertical RMSE</source>
            <translation>RMSE vertical</translation>
        </message>
        <message>
            <source>RMSE {rmse:.3f} m {relation} dz {limit:.3f} m ({how}); {beyond} of {n} points beyond it</source>
            <translation>RMSE {rmse:.3f} m {relation} dz {limit:.3f} m ({how}); {beyond} de {n} pontos além do limiar</translation>
        </message>
        <message>
            <source>Project threshold (Pedrosa &amp; dos Santos 2020, section 3)</source>
            <translation>Limiar do projeto (Pedrosa &amp; dos Santos 2020, seção 3)</translation>
        </message>
        <message>
            <source>The paper compares the RMSE of the check-point discrepancies with 0.40 m (twice the LiDAR standard deviation) and with dz of Eq. 18.</source>
            <translation>O artigo compara o RMSE das discrepâncias nos pontos de verificação com 0,40 m (o dobro do desvio-padrão do LiDAR) e com o dz da Eq. 18.</translation>
        </message>
        <message>
            <source>Horizontal discrepancy vectors</source>
            <translation>Vetores de discrepância horizontal</translation>
        </message>
        <message>
            <source>normal quantile</source>
            <translation>quantil normal</translation>
        </message>
        <message>
            <source>discrepancy (m)</source>
            <translation>discrepância (m)</translation>
        </message>
        <message>
            <source>(vectors x {})</source>
            <translation>(vetores x {})</translation>
        </message>
        <message>
            <source>mean residual per cell; {} px = {} px on screen; largest {} px</source>
            <translation>resíduo médio por célula; {} px = {} px na tela; maior {} px</translation>
        </message>
        <message>
            <source>{} m discrepancy</source>
            <translation>discrepância de {} m</translation>
        </message>
        <message>
            <source>Correlations between the APs and the station parameters (Lichti 2010) come from the network design, not the instrument: the rangefinder offset a0 with the station positions when the targets lie on one side or in a narrow vertical band; the collimation error b1 with kappa when the targets are near the horizon (sec(alpha) is then about 1); the trunnion-axis error b2 and the vertical index c0 with omega and phi. They are broken by targets all around the scanner and over the full vertical range (floor and ceiling), by two-face observations, and by stations whose scanner is tilted by about 90 degrees (which turn elevations into horizontal directions). A levelled scanner's compensator observes omega and phi and helps b2 and c0.</source>
            <translation>As correlações entre os PAs e os parâmetros das estações (Lichti 2010) vêm da geometria da rede, não do instrumento: o deslocamento do distanciômetro a0 com as posições das estações quando os alvos estão de um só lado ou em uma faixa vertical estreita; o erro de colimação b1 com kappa quando os alvos estão próximos do horizonte (sec(alfa) é então cerca de 1); o erro do eixo secundário b2 e o índice vertical c0 com omega e phi. Elas são quebradas por alvos em toda a volta do escâner e em toda a faixa vertical (piso e teto), por observações nas duas posições da luneta e por estações cujo escâner está inclinado de cerca de 90 graus (o que transforma elevações em direções horizontais). O compensador de um escâner nivelado observa omega e phi e ajuda b2 e c0.</translation>
        </message>
        <message>
            <source>The calibration FAILED its checks: no table and no registered scan were written. The numbers below show the failed adjustment, for diagnosis only.</source>
            <translation>A calibração FALHOU nas verificações: nenhuma tabela e nenhuma varredura registrada foram gravadas. Os números abaixo mostram o ajustamento que falhou, apenas para diagnóstico.</translation>
        </message>
        <message>
            <source>station / target</source>
            <translation>estação / alvo</translation>
        </message>
        <message>
            <source>v range mm</source>
            <translation>v distância mm</translation>
        </message>
        <message>
            <source>Stations</source>
            <translation>Estações</translation>
        </message>
        <message>
            <source>station</source>
            <translation>estação</translation>
        </message>
        <message>
            <source>levelled</source>
            <translation>nivelada</translation>
        </message>
        <message>
            <source>TLS self-calibration</source>
            <translation>Autocalibração TLS</translation>
        </message>
        <message>
            <source>Terrestrial laser scanner: registration and self-calibration</source>
            <translation>Laser scanner terrestre: registro e autocalibração</translation>
        </message>
        <message>
            <source>Model: Carvalho, Correa &amp;amp; dos Santos (Eqs. 1-5), additional parameters after Lichti (2007), correlation analysis after Lichti (2010).</source>
            <translation>Modelo: Carvalho, Correa &amp;amp; dos Santos (Eqs. 1-5), parâmetros adicionais segundo Lichti (2007), análise de correlação segundo Lichti (2010).</translation>
        </message>
        <message>
            <source>range</source>
            <translation>distância</translation>
        </message>
        <message>
            <source>horizontal direction</source>
            <translation>direção horizontal</translation>
        </message>
        <message>
            <source>arc-seconds</source>
            <translation>segundos de arco</translation>
        </message>
        <message>
            <source>vertical angle</source>
            <translation>ângulo vertical</translation>
        </message>
        <message>
            <source>observations (station-target-face)</source>
            <translation>observações (estação-alvo-posição)</translation>
        </message>
        <message>
            <source>stations / targets</source>
            <translation>estações / alvos</translation>
        </message>
        <message>
            <source>observations rejected (data snooping)</source>
            <translation>observações rejeitadas (data snooping)</translation>
        </message>
        <message>
            <source>datum</source>
            <translation>referencial (datum)</translation>
        </message>
        <message>
            <source>Additional parameters</source>
            <translation>Parâmetros adicionais</translation>
        </message>
        <message>
            <source>AP</source>
            <translation>PA</translation>
        </message>
        <message>
            <source>term</source>
            <translation>termo</translation>
        </message>
        <message>
            <source>cause</source>
            <translation>causa</translation>
        </message>
        <message>
            <source>sigma a-priori</source>
            <translation>sigma a priori</translation>
        </message>
        <message>
            <source>why, and the design that breaks it</source>
            <translation>por quê, e a geometria que a quebra</translation>
        </message>
        <message>
            <source>Automatic AP selection</source>
            <translation>Seleção automática de PAs</translation>
        </message>
        <message>
            <source>removed</source>
            <translation>removido</translation>
        </message>
        <message>
            <source>why</source>
            <translation>por quê</translation>
        </message>
        <message>
            <source>remaining</source>
            <translation>restantes</translation>
        </message>
        <message>
            <source>control</source>
            <translation>controle</translation>
        </message>
        <message>
            <source>inner constraints</source>
            <translation>injunções internas</translation>
        </message>
        <message>
            <source>t = |value| / sigma against the Student-t critical value {} (two-sided, alpha = {}). sigma is scaled by sigma0; sigma a-priori is the Cramer-Rao bound of the network for the observation sigmas given.</source>
            <translation>t = |valor| / sigma contra o valor crítico t de Student {} (bilateral, alfa = {}). sigma é escalado por sigma0; sigma a priori é o limite de Cramér-Rao da rede para os desvios-padrão de observação informados.</translation>
        </message>
        <message>
            <source>Pairs with |r| &amp;ge; {}:</source>
            <translation>Pares com |r| &amp;ge; {}:</translation>
        </message>
        <message>
            <source>No pair involving an AP reaches |r| = {}.</source>
            <translation>Nenhum par envolvendo um PA atinge |r| = {}.</translation>
        </message>
        <message>
            <source>NOT</source>
            <translation>NÃO</translation>
        </message>
        <message>
            <source>|correlation| {r:.3f} &gt; {limit:g} with {other}</source>
            <translation type="vanished">|correlação| {r:.3f} &gt; {limit:g} com {other}</translation>
        </message>
        <message>
            <source>mean planimetric (m)</source>
            <translation type="vanished">média planimétrica (m)</translation>
        </message>
        <message>
            <source>std planimetric (m)</source>
            <translation type="vanished">desvio-padrão planimétrico (m)</translation>
        </message>
        <message>
            <source>RMS planimetric (m)</source>
            <translation type="vanished">RMS planimétrico (m)</translation>
        </message>
        <message>
            <source>RMS height (m)</source>
            <translation type="vanished">RMS em altura (m)</translation>
        </message>
        <message>
            <source>planimetric (m)</source>
            <translation type="vanished">planimétrica (m)</translation>
        </message>
        <message>
            <source>Planimetric discrepancy: mean {} m, standard deviation {} m, RMS {} m; RMS E/N/H {} / {} / {} m; 3D {} m. Intersected with the adjusted orientations; their sigmas carry the image noise only.</source>
            <translation type="vanished">Discrepância planimétrica: média {} m, desvio-padrão {} m, RMS {} m; RMS E/N/H {} / {} / {} m; 3D {} m. Intersectados com as orientações ajustadas; os seus desvios-padrão trazem apenas o ruído das imagens.</translation>
        </message>
    </context>
    <context>
        <name>ResectionController</name>
        <message>
            <source>A resection is already running.</source>
            <translation>Uma resseção já está em execução.</translation>
        </message>
        <message>
            <source>No observations in image {}.</source>
            <translation>Não há observações na imagem {}.</translation>
        </message>
        <message>
            <source>The observations could not be saved.</source>
            <translation>Não foi possível salvar as observações.</translation>
        </message>
        <message>
            <source>Choose the line or LCP layer.</source>
            <translation>Escolha a camada de linhas ou de LCPs.</translation>
        </message>
        <message>
            <source>Image {} has only line rows: camera {} has the {} (fisheye) projection, and the resection from lines handles perspective cameras only. Measure control points (lcp).</source>
            <translation>A imagem {} tem apenas linhas do tipo line: a câmera {} tem a projeção {} (olho de peixe), e a resseção a partir de linhas trata apenas câmeras perspectivas. Meça pontos de controle (lcp).</translation>
        </message>
        <message>
            <source>{} line row(s) of image {} left out: the resection from lines handles perspective cameras only (camera {}: {} fisheye projection).</source>
            <translation>{} linha(s) do tipo line da imagem {} deixada(s) de fora: a resseção a partir de linhas trata apenas câmeras perspectivas (câmera {}: projeção olho de peixe {}).</translation>
        </message>
        <message>
            <source>Resection of {}</source>
            <translation>Resseção de {}</translation>
        </message>
        <message>
            <source>Resection cancelled.</source>
            <translation>Resseção cancelada.</translation>
        </message>
        <message>
            <source>Resection failed. {}</source>
            <translation>A resseção falhou. {}</translation>
        </message>
        <message>
            <source>Resection of {} done: sigma0 {}; {}</source>
            <translation>Resseção de {} concluída: sigma0 {}; {}</translation>
        </message>
    </context>
    <context>
        <name>ResectionPanel</name>
        <message>
            <source>Resect the image shown</source>
            <translation>Fazer a resseção da imagem exibida</translation>
        </message>
        <message>
            <source>Runs {} in the background: the image's exterior orientation from its measured lines and control points, no approximate values</source>
            <translation>Executa {} em segundo plano: a orientação exterior da imagem a partir de suas linhas e pontos de controle medidos, sem valores aproximados</translation>
        </message>
        <message>
            <source>Refine line ends on the image edge</source>
            <translation>Refinar as extremidades da linha sobre a borda na imagem</translation>
        </message>
        <message>
            <source>Line picking: each click moves across the line to the strongest grey-value edge within 4 px (sub-pixel)</source>
            <translation>Medição de linhas: cada clique se desloca transversalmente à linha até a borda de nível de cinza mais forte a até 4 px (subpixel)</translation>
        </message>
        <message>
            <source>Resection running…</source>
            <translation>Resseção em execução…</translation>
        </message>
        <message>
            <source>σ0 {:.3f}, redundancy {}, χ² test {}; {} point(s), {} line(s)</source>
            <translation>σ0 {:.3f}, redundância {}, teste χ² {}; {} ponto(s), {} linha(s)</translation>
        </message>
        <message>
            <source>passed</source>
            <translation>aprovado</translation>
        </message>
        <message>
            <source>FAILED</source>
            <translation>REPROVADO</translation>
        </message>
        <message>
            <source>type</source>
            <translation>tipo</translation>
        </message>
        <message>
            <source>id</source>
            <translation>id</translation>
        </message>
        <message>
            <source>pts</source>
            <translation>pts</translation>
        </message>
        <message>
            <source>RMS px</source>
            <translation>RMS px</translation>
        </message>
        <message>
            <source>max px</source>
            <translation>máx. px</translation>
        </message>
        <message>
            <source>rejected</source>
            <translation>rejeitado</translation>
        </message>
    </context>
    <context>
        <name>ViewerPanel</name>
        <message>
            <source>Type of the next point (T/P/L/C/K)</source>
            <translation>Tipo do próximo ponto (T/P/L/C/K)</translation>
        </message>
        <message>
            <source>Undo (Ctrl+Z)</source>
            <translation>Desfazer (Ctrl+Z)</translation>
        </message>
        <message>
            <source>Redo (Ctrl+Shift+Z)</source>
            <translation>Refazer (Ctrl+Shift+Z)</translation>
        </message>
        <message>
            <source>Magnifier (M)</source>
            <translation>Lupa (M)</translation>
        </message>
        <message>
            <source>Monoplot</source>
            <translation>Monorrestituir</translation>
        </message>
        <message>
            <source>Monoplotting: clicks become 3D points (or line vertices) on the DSM, added to the map at once; off: clicks measure observations again</source>
            <translation>Monorrestituição: os cliques tornam-se pontos 3D (ou vértices de linha) sobre o MDS, adicionados ao mapa imediatamente; desligada: os cliques voltam a medir observações</translation>
        </message>
        <message>
            <source>points</source>
            <translation>pontos</translation>
        </message>
        <message>
            <source>lines</source>
            <translation>linhas</translation>
        </message>
        <message>
            <source>Monoplot points, or lines (finish: Enter)</source>
            <translation>Monorrestituir pontos ou linhas (terminar: Enter)</translation>
        </message>
        <message>
            <source>Finish line</source>
            <translation>Terminar linha</translation>
        </message>
        <message>
            <source>End the line being digitised (also Enter or a double click)</source>
            <translation>Termina a linha em digitalização (também Enter ou um clique duplo)</translation>
        </message>
        <message>
            <source>Save the monoplotted points and lines to a GeoPackage</source>
            <translation>Salvar os pontos e linhas monorrestituídos em um GeoPackage</translation>
        </message>
        <message>
            <source>Refine</source>
            <translation>Refinar</translation>
        </message>
        <message>
            <source>Snap the selected point to the least-squares match (6 affine + 2 radiometric parameters) of the same point measured in another image</source>
            <translation>Ajusta o ponto selecionado à correspondência por mínimos quadrados (6 parâmetros afins + 2 radiométricos) do mesmo ponto medido em outra imagem</translation>
        </message>
        <message>
            <source>planes</source>
            <translation>planos</translation>
        </message>
        <message>
            <source>lcps</source>
            <translation>LCPs</translation>
        </message>
        <message>
            <source>residuals</source>
            <translation>resíduos</translation>
        </message>
        <message>
            <source>observations</source>
            <translation>observações</translation>
        </message>
        <message>
            <source>predictions</source>
            <translation>previsões</translation>
        </message>
        <message>
            <source>Scale of the residual vectors</source>
            <translation>Escala dos vetores de resíduos</translation>
        </message>
        <message>
            <source>no orientation</source>
            <translation>sem orientação</translation>
        </message>
        <message>
            <source>no file</source>
            <translation>sem arquivo</translation>
        </message>
        <message>
            <source>missing on disk</source>
            <translation>ausente do disco</translation>
        </message>
        <message>
            <source>file missing on disk</source>
            <translation>arquivo ausente do disco</translation>
        </message>
        <message>
            <source>no image file</source>
            <translation>sem arquivo de imagem</translation>
        </message>
        <message>
            <source>add it with Images &gt; Add</source>
            <translation>adicione-a com Imagens &gt; Adicionar</translation>
        </message>
        <message>
            <source>Image {}: {} ({}).</source>
            <translation>Imagem {}: {} ({}).</translation>
        </message>
        <message>
            <source>Image {} has no exterior orientation: no overlays, no picking.</source>
            <translation>A imagem {} não tem orientação exterior: sem sobreposições, sem medição.</translation>
        </message>
        <message>
            <source>Image {} is {} x {} px but the camera is {} x {} px.</source>
            <translation>A imagem {} tem {} x {} px, mas a câmera tem {} x {} px.</translation>
        </message>
        <message>
            <source>Image {}: {} x {} px, {} band(s), {}.</source>
            <translation>Imagem {}: {} x {} px, {} banda(s), {}.</translation>
        </message>
    </context>
    <context>
        <name>lidarphoto:accuracyreport</name>
        <message>
            <source>Positional accuracy report</source>
            <translation>Relatório de acurácia posicional</translation>
        </message>
        <message>
            <source>Accuracy</source>
            <translation>Acurácia</translation>
        </message>
        <message>
            <source>check points against ASPRS Ed. 2, NSSDA, PEC-PCD and the project threshold</source>
            <translation>pontos de verificação segundo ASPRS Ed. 2, NSSDA, PEC-PCD e o limiar do projeto</translation>
        </message>
        <message>
            <source>Compares measured check points with reference coordinates and reports their positional
accuracy: discrepancies d = measured - reference (dE, dN, dH, horizontal, 3D), mean, standard
deviation, RMSE, minimum and maximum per component, per group and overall; Shapiro-Wilk
normality, Student's t test for bias, chi-square test of the standard deviation against a
declared precision; outlier screening (flagged points are reported, excluded only on
request); and the verdicts of the ASPRS Positional Accuracy Standards Edition 2 (2023),
NSSDA (FGDC-STD-007.3-1998), the Brazilian PEC-PCD (classes A-D for a scale) and the project
threshold of Pedrosa &amp; dos Santos (2020): 0.40 m planimetric, dz = sqrt(2) H^2 / (B f)
sigma_pix.</source>
            <translation>Compara pontos de verificação medidos com coordenadas de referência e relata sua acurácia
posicional: discrepâncias d = medido - referência (dE, dN, dH, horizontal, 3D), média,
desvio-padrão, RMSE, mínimo e máximo por componente, por grupo e no total; teste de normalidade
de Shapiro-Wilk, teste t de Student para tendência, teste qui-quadrado do desvio-padrão contra
uma precisão declarada; triagem de outliers (os pontos marcados são relatados e excluídos
apenas a pedido); e os vereditos dos Padrões de Acurácia Posicional da ASPRS, Edição 2 (2023),
do NSSDA (FGDC-STD-007.3-1998), do PEC-PCD brasileiro (classes A-D para uma escala) e do limiar
de projeto de Pedrosa &amp; dos Santos (2020): 0,40 m planimétrico, dz = sqrt(2) H^2 / (B f)
sigma_pix.</translation>
        </message>
        <message>
            <source>## Input: one table or two point tables/layers
Check-point table (CSV): id, e, n, h (measured) and e_ref, n_ref, h_ref (reference),
optional group; metres in one projected CRS (give it as CRS).</source>
            <translation>## Entrada: uma tabela ou duas tabelas/camadas de pontos
Tabela de pontos de verificação (CSV): id, e, n, h (medidos) e e_ref, n_ref, h_ref
(referência), group opcional; metros em um SRC projetado (informe-o em SRC).</translation>
        </message>
        <message>
            <source>Or Measured points and Reference points (CSV tables id, e, n, h [, group], or point layers in
QGIS) joined by their ids. Ids present in only one set, duplicate ids and missing coordinates
are errors. Layers in different CRSs are refused unless Reproject is checked (QGIS only: the
reference layer is then transformed to the measured layer's CRS, heights unchanged).</source>
            <translation>Ou Pontos medidos e Pontos de referência (tabelas CSV id, e, n, h [, group], ou camadas de
pontos no QGIS) associados por seus identificadores. Identificadores presentes em apenas um
conjunto, identificadores repetidos e coordenadas ausentes são erros. Camadas em SRCs
diferentes são recusadas, a menos que Reprojetar esteja marcado (somente no QGIS: a camada de
referência é então transformada para o SRC da camada medida, alturas inalteradas).</translation>
        </message>
        <message>
            <source>## Settings
Declared precision and check-point survey sigma are per horizontal axis and in height (m;
0 = not given). ASPRS classes in cm (0 = report the tightest class met); PEC-PCD scale
denominator, equidistance (0 = the series' value) and declared class; project thresholds
(vertical 0 = dz of Eq. 18 from the flight geometry "H m, B m, f mm, pixel um").</source>
            <translation>## Configurações
A precisão declarada e o sigma do levantamento dos pontos de verificação são por eixo
horizontal e em altura (m; 0 = não informado). Classes ASPRS em cm (0 = relatar a classe mais
rigorosa atendida); denominador da escala do PEC-PCD, equidistância (0 = o valor da série) e
classe declarada; limiares do projeto (vertical 0 = dz da Eq. 18 a partir da geometria do voo
"H m, B m, f mm, pixel um").</translation>
        </message>
        <message>
            <source>## Outputs
A self-contained HTML report (tables, verdicts, SVG plots), a JSON of every figure, a PointZ
layer at the reference positions with id, group, dE, dN, dU, dHorizontal, d3D, outlier, and
the RMSE values as numeric outputs RMSE_E, RMSE_N, RMSE_U (height), RMSE_HORIZONTAL, RMSE_3D
(docs/formats.md, "Accuracy figures"; RMSE_H and RMSE_HORIZ, their former names, are kept
for one release).</source>
            <translation>## Saídas
Um relatório HTML autocontido (tabelas, vereditos, gráficos SVG), um JSON com todos os valores, uma camada
PointZ nas posições de referência com id, group, dE, dN, dU, dHorizontal, d3D, outlier, e
os valores de RMSE como saídas numéricas RMSE_E, RMSE_N, RMSE_U (altura), RMSE_HORIZONTAL, RMSE_3D
(docs/formats.md, "Accuracy figures"; RMSE_H e RMSE_HORIZ, os seus nomes anteriores, são mantidos
por uma versão).</translation>
        </message>
        <message>
            <source>Check-point table (CSV: id, e, n, h, e_ref, n_ref, h_ref, group)</source>
            <translation>Tabela de pontos de verificação (CSV: id, e, n, h, e_ref, n_ref, h_ref, group)</translation>
        </message>
        <message>
            <source>CSV files (*.csv *.txt)</source>
            <translation>Arquivos CSV (*.csv *.txt)</translation>
        </message>
        <message>
            <source>Measured points</source>
            <translation>Pontos medidos</translation>
        </message>
        <message>
            <source>measured point table (CSV: id, e, n, h [, group]) or point layer</source>
            <translation>tabela de pontos medidos (CSV: id, e, n, h [, group]) ou camada de pontos</translation>
        </message>
        <message>
            <source>Measured id field</source>
            <translation>Campo de identificador dos pontos medidos</translation>
        </message>
        <message>
            <source>id column (default: id)</source>
            <translation>coluna de identificador (padrão: id)</translation>
        </message>
        <message>
            <source>Measured height field (empty: geometry Z)</source>
            <translation>Campo de altura dos pontos medidos (vazio: Z da geometria)</translation>
        </message>
        <message>
            <source>height column (default: h; in QGIS empty takes the geometry's Z)</source>
            <translation>coluna de altura (padrão: h; no QGIS, vazio usa o Z da geometria)</translation>
        </message>
        <message>
            <source>Reference points</source>
            <translation>Pontos de referência</translation>
        </message>
        <message>
            <source>reference point table (CSV: id, e, n, h [, group]) or point layer</source>
            <translation>tabela de pontos de referência (CSV: id, e, n, h [, group]) ou camada de pontos</translation>
        </message>
        <message>
            <source>Reference id field</source>
            <translation>Campo de identificador dos pontos de referência</translation>
        </message>
        <message>
            <source>Reference height field (empty: geometry Z)</source>
            <translation>Campo de altura dos pontos de referência (vazio: Z da geometria)</translation>
        </message>
        <message>
            <source>Group field (flight direction, model, block)</source>
            <translation>Campo de grupo (direção de voo, modelo, bloco)</translation>
        </message>
        <message>
            <source>group column (default: group)</source>
            <translation>coluna de grupo (padrão: group)</translation>
        </message>
        <message>
            <source>CRS of the check-point table</source>
            <translation>SRC da tabela de pontos de verificação</translation>
        </message>
        <message>
            <source>CRS of the coordinates (reported only)</source>
            <translation>SRC das coordenadas (apenas relatado)</translation>
        </message>
        <message>
            <source>Reproject the reference layer to the measured CRS</source>
            <translation>Reprojetar a camada de referência para o SRC dos pontos medidos</translation>
        </message>
        <message>
            <source>QGIS only: point tables carry no CRS</source>
            <translation>Somente no QGIS: tabelas de pontos não têm SRC</translation>
        </message>
        <message>
            <source>Significance level of the tests</source>
            <translation>Nível de significância dos testes</translation>
        </message>
        <message>
            <source>Declared precision per horizontal axis</source>
            <translation>Precisão declarada por eixo horizontal</translation>
        </message>
        <message>
            <source>Declared precision in height</source>
            <translation>Precisão declarada em altura</translation>
        </message>
        <message>
            <source>Check-point survey sigma per horizontal axis</source>
            <translation>Sigma do levantamento dos pontos de verificação por eixo horizontal</translation>
        </message>
        <message>
            <source>Check-point survey sigma in height</source>
            <translation>Sigma do levantamento dos pontos de verificação em altura</translation>
        </message>
        <message>
            <source>Outlier screening</source>
            <translation>Triagem de outliers</translation>
        </message>
        <message>
            <source>robust: modified z-score &gt; 3.5 (median/MAD)</source>
            <translation>robusta: escore z modificado &gt; 3,5 (mediana/MAD)</translation>
        </message>
        <message>
            <source>three sigma: |d - mean| &gt; 3 s</source>
            <translation>três sigmas: |d - média| &gt; 3 s</translation>
        </message>
        <message>
            <source>none</source>
            <translation>nenhuma</translation>
        </message>
        <message>
            <source>Exclude flagged outliers from the statistics</source>
            <translation>Excluir das estatísticas os outliers marcados</translation>
        </message>
        <message>
            <source>Standards</source>
            <translation>Padrões</translation>
        </message>
        <message>
            <source>ASPRS Positional Accuracy Standards, Edition 2 (2023)</source>
            <translation>Padrões de Acurácia Posicional da ASPRS, Edição 2 (2023)</translation>
        </message>
        <message>
            <source>NSSDA (FGDC-STD-007.3-1998)</source>
            <translation>NSSDA (FGDC-STD-007.3-1998)</translation>
        </message>
        <message>
            <source>PEC-PCD (Decreto 89.817 / ET-CQDG)</source>
            <translation>PEC-PCD (Decreto 89.817 / ET-CQDG)</translation>
        </message>
        <message>
            <source>Project threshold (Pedrosa &amp; dos Santos 2020: 0.40 m, dz of Eq. 18)</source>
            <translation>Limiar do projeto (Pedrosa &amp; dos Santos 2020: 0,40 m, dz da Eq. 18)</translation>
        </message>
        <message>
            <source>ASPRS horizontal class (0 = tightest met)</source>
            <translation>Classe horizontal ASPRS (0 = a mais rigorosa atendida)</translation>
        </message>
        <message>
            <source>ASPRS vertical class (0 = tightest met)</source>
            <translation>Classe vertical ASPRS (0 = a mais rigorosa atendida)</translation>
        </message>
        <message>
            <source>PEC-PCD scale denominator (1:N)</source>
            <translation>Denominador da escala do PEC-PCD (1:N)</translation>
        </message>
        <message>
            <source>PEC-PCD equidistance (0 = series value)</source>
            <translation>Equidistância do PEC-PCD (0 = valor da série)</translation>
        </message>
        <message>
            <source>PEC-PCD declared class</source>
            <translation>Classe declarada do PEC-PCD</translation>
        </message>
        <message>
            <source>Project planimetric threshold</source>
            <translation>Limiar planimétrico do projeto</translation>
        </message>
        <message>
            <source>Project vertical threshold (0 = Eq. 18)</source>
            <translation>Limiar vertical do projeto (0 = Eq. 18)</translation>
        </message>
        <message>
            <source>Flight geometry for Eq. 18: H, B, f, pixel</source>
            <translation>Geometria do voo para a Eq. 18: H, B, f, pixel</translation>
        </message>
        <message>
            <source>Check points with discrepancies</source>
            <translation>Pontos de verificação com discrepâncias</translation>
        </message>
        <message>
            <source>Accuracy report (HTML)</source>
            <translation>Relatório de acurácia (HTML)</translation>
        </message>
        <message>
            <source>HTML files (*.html)</source>
            <translation>Arquivos HTML (*.html)</translation>
        </message>
        <message>
            <source>Accuracy figures (JSON)</source>
            <translation>Valores de acurácia (JSON)</translation>
        </message>
        <message>
            <source>JSON files (*.json)</source>
            <translation>Arquivos JSON (*.json)</translation>
        </message>
        <message>
            <source>RMSE_E (m)</source>
            <translation>RMSE_E (m)</translation>
        </message>
        <message>
            <source>RMSE_N (m)</source>
            <translation>RMSE_N (m)</translation>
        </message>
        <message>
            <source>RMSE_U (m)</source>
            <translation>RMSE_U (m)</translation>
        </message>
        <message>
            <source>RMSE_HORIZONTAL (m)</source>
            <translation>RMSE_HORIZONTAL (m)</translation>
        </message>
        <message>
            <source>RMSE_3D (m)</source>
            <translation>RMSE_3D (m)</translation>
        </message>
        <message>
            <source>RMSE_H (m; deprecated: use RMSE_U)</source>
            <translation>RMSE_H (m; obsoleto: use RMSE_U)</translation>
        </message>
        <message>
            <source>RMSE_HORIZ (m; deprecated: use RMSE_HORIZONTAL)</source>
            <translation>RMSE_HORIZ (m; obsoleto: use RMSE_HORIZONTAL)</translation>
        </message>
        <message>
            <source>Quality</source>
            <translation type="vanished">Qualidade</translation>
        </message>
        <message>
            <source>## Outputs
A self-contained HTML report (tables, verdicts, SVG plots), a JSON of every figure, a PointZ
layer at the reference positions with id, group, dE, dN, dH, dHoriz, d3D, outlier, and the
RMSE values as numeric outputs.</source>
            <translation type="vanished">## Saídas
Um relatório HTML autocontido (tabelas, vereditos, gráficos SVG), um JSON com todos os valores,
uma camada PointZ nas posições de referência com id, group, dE, dN, dH, dHoriz, d3D, outlier, e
os valores de RMSE como saídas numéricas.</translation>
        </message>
        <message>
            <source>RMSE_H (m)</source>
            <translation type="vanished">RMSE_H (m)</translation>
        </message>
        <message>
            <source>RMSE_HORIZ (m)</source>
            <translation type="vanished">RMSE_HORIZ (m)</translation>
        </message>
    </context>
    <context>
        <name>lidarphoto:autoboresight</name>
        <message>
            <source>Automatic boresight calibration</source>
            <translation>Calibração de boresight automática</translation>
        </message>
        <message>
            <source>Calibration</source>
            <translation>Calibração</translation>
        </message>
        <message>
            <source>boresight without hand picks: image edges along LiDAR lines, ties on roof planes</source>
            <translation>boresight sem medições manuais: bordas da imagem ao longo das linhas LiDAR, pontos de enlace nos planos de telhado</translation>
        </message>
        <message>
            <source>Calibrates the camera-INS boresight from the images themselves, with no picked point. The
LiDAR ridge, hip and valley lines (the line table of Create LiDAR control points and lines)
are projected into every image with the trajectory, the mount and the approximate boresight.
First an angle search (coarse to fine, within Search range of the approximate boresight)
finds the boresight whose projected lines lie on the strongest image edges; then, in rounds,
sub-pixel image edges are found along every projected line (the dock's edge refinement, within
3 sigma of the projection's uncertainty) and each tie track (found between the images by
the chain of Automatic tie points, pairs from the footprints and least-squares refinement on,
or its observation CSV given as Tie points) is intersected and kept as a point-to-plane tie of
the roof plane it lies on (inside the plane's outline, from the cloud's plane ids; off the
borders; within a gate of 3 sigma of the pose and intersection uncertainty; not on a wall).
Each round runs the rigorous calibration of Boresight calibration (line and tie models,
INS priors, data snooping) and starts the next from its result, until every angle changes
by less than its standard deviation.</source>
            <translation>Calibra o boresight câmera-INS a partir das próprias imagens, sem nenhum ponto medido. As
linhas LiDAR de cumeeira, espigão e rincão (a tabela de linhas de Criar pontos e linhas de
controle LiDAR) são projetadas em cada imagem com a trajetória, a montagem e o boresight
aproximado. Primeiro uma busca angular (do grosseiro ao fino, dentro do Intervalo de busca em
torno do boresight aproximado) encontra o boresight cujas linhas projetadas caem sobre as bordas
mais fortes da imagem; depois, em rodadas, bordas subpixel são encontradas ao longo de cada
linha projetada (o refinamento de bordas do painel, dentro de 3 sigma da incerteza da projeção)
e cada trilha de pontos de enlace (encontrada entre as imagens pela cadeia de Pontos de enlace
automáticos, pares pelas áreas de cobertura e refinamento por mínimos quadrados ativo, ou o seu
CSV de observações dado como Pontos de enlace) é intersectada e mantida como vínculo ponto-plano
do plano de telhado onde está (dentro do contorno do plano, pelos ids de plano da nuvem; longe
das bordas; dentro de uma janela de 3 sigma da incerteza da pose e da interseção; fora de
paredes). Cada rodada executa a calibração rigorosa de Calibração de boresight (modelos de linha
e de enlace, injunções do INS, data snooping) e inicia a seguinte a partir do seu resultado, até
que cada ângulo mude menos que seu desvio-padrão.</translation>
        </message>
        <message>
            <source>A scene with no sloped roof plane and fewer than two LiDAR line directions (flat ground,
flat roofs) is refused: the angles are not observable there.</source>
            <translation>Uma cena sem plano de telhado inclinado e com menos de duas direções de linhas LiDAR (terreno
plano, telhados planos) é recusada: ali os ângulos não são observáveis.</translation>
        </message>
        <message>
            <source>Outputs: the boresight per group and the updated exterior orientation (as Boresight
calibration), the observations found (image-observation CSV: Boresight calibration reads it
again, e.g. to compare with hand picks), the rounds (CSV) and the HTML summary, whose settings
give the counts per round and the ties refused per reason.</source>
            <translation>Saídas: o boresight por grupo e a orientação exterior atualizada (como em Calibração de
boresight), as observações encontradas (CSV de observações de imagem: Calibração de boresight o
lê de novo, p. ex. para comparar com medições manuais), as rodadas (CSV) e o resumo HTML, cujas
configurações dão as contagens por rodada e os pontos de enlace recusados por motivo.</translation>
        </message>
        <message>
            <source>Images (files or folders)</source>
            <translation>Imagens (arquivos ou pastas)</translation>
        </message>
        <message>
            <source>the image id is the file name without extension, as in the trajectory</source>
            <translation>o id da imagem é o nome do arquivo sem extensão, como na trajetória</translation>
        </message>
        <message>
            <source>Camera (JSON)</source>
            <translation>Câmera (JSON)</translation>
        </message>
        <message>
            <source>JSON files (*.json)</source>
            <translation>Arquivos JSON (*.json)</translation>
        </message>
        <message>
            <source>Trajectory table (CSV)</source>
            <translation>Tabela da trajetória (CSV)</translation>
        </message>
        <message>
            <source>CSV files (*.csv *.txt)</source>
            <translation>Arquivos CSV (*.csv *.txt)</translation>
        </message>
        <message>
            <source>Mapping CRS</source>
            <translation>SRC de mapeamento</translation>
        </message>
        <message>
            <source>projected CRS of the trajectory and of the LiDAR tables</source>
            <translation>SRC projetado da trajetória e das tabelas LiDAR</translation>
        </message>
        <message>
            <source>Lever arm x,y,z</source>
            <translation>Braço de alavanca x,y,z</translation>
        </message>
        <message>
            <source>camera perspective centre in the INS body frame (x forward, y right, z down)</source>
            <translation>centro perspectivo da câmera no referencial do corpo do INS (x para a frente, y para a direita, z para baixo)</translation>
        </message>
        <message>
            <source>Camera mount</source>
            <translation>Montagem da câmera</translation>
        </message>
        <message>
            <source>nominal camera-to-body rotation; custom uses MOUNT_MATRIX</source>
            <translation>rotação nominal da câmera para o corpo; custom usa MOUNT_MATRIX</translation>
        </message>
        <message>
            <source>image_top_forward: image top towards the flight direction (nose)</source>
            <translation>image_top_forward: topo da imagem no sentido do voo (nariz)</translation>
        </message>
        <message>
            <source>image_right_forward: image right side towards the flight direction</source>
            <translation>image_right_forward: lado direito da imagem no sentido do voo</translation>
        </message>
        <message>
            <source>image_bottom_forward: image bottom towards the flight direction</source>
            <translation>image_bottom_forward: base da imagem no sentido do voo</translation>
        </message>
        <message>
            <source>image_left_forward: image left side towards the flight direction</source>
            <translation>image_left_forward: lado esquerdo da imagem no sentido do voo</translation>
        </message>
        <message>
            <source>custom: custom matrix (MOUNT_MATRIX)</source>
            <translation>custom: matriz definida pelo usuário (MOUNT_MATRIX)</translation>
        </message>
        <message>
            <source>Mount matrix R_c^b (9 numbers, row-major)</source>
            <translation>Matriz de montagem R_c^b (9 números, por linhas)</translation>
        </message>
        <message>
            <source>the nominal mount R_c^b when MOUNT is custom</source>
            <translation>a montagem nominal R_c^b quando MOUNT é custom</translation>
        </message>
        <message>
            <source>Boresight domega,dphi,dkappa</source>
            <translation>Boresight domega,dphi,dkappa</translation>
        </message>
        <message>
            <source>small misalignment about the camera axes x, y, z (a larger rotation belongs in MOUNT)</source>
            <translation>pequeno desalinhamento em torno dos eixos x, y, z da câmera (uma rotação maior pertence a MOUNT)</translation>
        </message>
        <message>
            <source>Line table (CSV)</source>
            <translation>Tabela de linhas (CSV)</translation>
        </message>
        <message>
            <source>Plane table (CSV)</source>
            <translation>Tabela de planos (CSV)</translation>
        </message>
        <message>
            <source>the roof planes of the tie points and of the observability check</source>
            <translation>os planos de telhado dos pontos de enlace e da verificação de observabilidade</translation>
        </message>
        <message>
            <source>Cloud with plane ids (LAS/LAZ)</source>
            <translation>Nuvem com identificadores de plano (LAS/LAZ)</translation>
        </message>
        <message>
            <source>the planes' outlines (convex hull of their points): needed by tie points</source>
            <translation>os contornos dos planos (envoltória convexa de seus pontos): necessários aos pontos de enlace</translation>
        </message>
        <message>
            <source>LAS/LAZ files (*.las *.laz *.LAS *.LAZ)</source>
            <translation>Arquivos LAS/LAZ (*.las *.laz *.LAS *.LAZ)</translation>
        </message>
        <message>
            <source>Tie points (observation CSV)</source>
            <translation>Pontos de enlace (CSV de observações)</translation>
        </message>
        <message>
            <source>the output of Automatic tie points</source>
            <translation>a saída de Pontos de enlace automáticos</translation>
        </message>
        <message>
            <source>Find tie points when none are given</source>
            <translation>Encontrar pontos de enlace quando nenhum é dado</translation>
        </message>
        <message>
            <source>without TIE_POINTS, and with PLANES and CLOUD, run Automatic tie points on the images (pairs from the footprints, least-squares refinement on)</source>
            <translation>sem TIE_POINTS, e com PLANES e CLOUD, executa Pontos de enlace automáticos nas imagens (pares pelas áreas de cobertura, refinamento por mínimos quadrados ativo)</translation>
        </message>
        <message>
            <source>Hand picks to compare with (observation CSV)</source>
            <translation>Medições manuais para comparar (CSV de observações)</translation>
        </message>
        <message>
            <source>observations picked in the dock: their tie and line rows are calibrated alone and the summary compares the two boresights</source>
            <translation>observações medidas no painel: suas linhas de enlace e de linha são calibradas sozinhas e o resumo compara os dois boresights</translation>
        </message>
        <message>
            <source>Search range of the boresight</source>
            <translation>Intervalo de busca do boresight</translation>
        </message>
        <message>
            <source>half width of the angle search about BORESIGHT (0: none)</source>
            <translation>meia largura da busca angular em torno de BORESIGHT (0: nenhuma)</translation>
        </message>
        <message>
            <source>Most rounds</source>
            <translation>Máximo de rodadas</translation>
        </message>
        <message>
            <source>Boresight groups</source>
            <translation>Grupos de boresight</translation>
        </message>
        <message>
            <source>one boresight for all images</source>
            <translation>um boresight para todas as imagens</translation>
        </message>
        <message>
            <source>one per trajectory group (flight line, direction, session)</source>
            <translation>um por grupo da trajetória (faixa de voo, direção, sessão)</translation>
        </message>
        <message>
            <source>one per heading direction (octant)</source>
            <translation>um por direção de rumo (octante)</translation>
        </message>
        <message>
            <source>Estimate the lever arm</source>
            <translation>Estimar o braço de alavanca</translation>
        </message>
        <message>
            <source>Estimate focal length and principal point</source>
            <translation>Estimar a distância focal e o ponto principal</translation>
        </message>
        <message>
            <source>Estimate the camera timing offset</source>
            <translation>Estimar o atraso de disparo da câmera</translation>
        </message>
        <message>
            <source>a constant dt (exposure = recorded time + dt) from the trajectory's velocities (v_north, v_east, v_up columns, as Import trajectory writes them) or from neighbouring exposures of each line; with the lever arm it needs lines at clearly different speeds</source>
            <translation>um dt constante (exposição = tempo registrado + dt) a partir das velocidades da trajetória (colunas v_north, v_east, v_up, como Importar trajetória as escreve) ou das exposições vizinhas de cada faixa; com o braço de alavanca exige faixas a velocidades claramente diferentes</translation>
        </message>
        <message>
            <source>INS grade</source>
            <translation>Classe do INS</translation>
        </message>
        <message>
            <source>Applanix POS AV 310</source>
            <translation>Applanix POS AV 310</translation>
        </message>
        <message>
            <source>custom (INS sigmas)</source>
            <translation>personalizada (sigmas do INS)</translation>
        </message>
        <message>
            <source>Custom INS sigmas: horizontal, vertical, roll/pitch, heading</source>
            <translation>Sigmas do INS personalizados: horizontal, vertical, rolagem/arfagem, rumo</translation>
        </message>
        <message>
            <source>Largest plausible boresight angle</source>
            <translation>Maior ângulo de boresight plausível</translation>
        </message>
        <message>
            <source>an estimated angle beyond this fails the run</source>
            <translation>um ângulo estimado além deste faz a execução falhar</translation>
        </message>
        <message>
            <source>Largest sigma0 when the global test fails</source>
            <translation>Maior sigma0 quando o teste global falha</translation>
        </message>
        <message>
            <source>a failed global test with sigma0 above this fails the run</source>
            <translation>um teste global reprovado com sigma0 acima deste faz a execução falhar</translation>
        </message>
        <message>
            <source>Write the results even when the checks fail</source>
            <translation>Gravar os resultados mesmo quando as verificações falham</translation>
        </message>
        <message>
            <source>no convergence, global test beyond MAX_SIGMA0, more rejections than false alarms explain or boresight beyond MAX_BORESIGHT: write the outputs anyway, each with a warning at its top</source>
            <translation>sem convergência, teste global além de MAX_SIGMA0, mais rejeições do que os falsos alarmes explicam ou boresight além de MAX_BORESIGHT: grava as saídas mesmo assim, cada uma com um aviso no início</translation>
        </message>
        <message>
            <source>Boresight per group (CSV)</source>
            <translation>Boresight por grupo (CSV)</translation>
        </message>
        <message>
            <source>CSV files (*.csv)</source>
            <translation>Arquivos CSV (*.csv)</translation>
        </message>
        <message>
            <source>Updated exterior orientation (CSV)</source>
            <translation>Orientação exterior atualizada (CSV)</translation>
        </message>
        <message>
            <source>Observations found (CSV)</source>
            <translation>Observações encontradas (CSV)</translation>
        </message>
        <message>
            <source>Rounds (CSV)</source>
            <translation>Rodadas (CSV)</translation>
        </message>
        <message>
            <source>Summary (HTML)</source>
            <translation>Resumo (HTML)</translation>
        </message>
        <message>
            <source>HTML files (*.html)</source>
            <translation>Arquivos HTML (*.html)</translation>
        </message>
        <message>
            <source>Sigma0 a-posteriori</source>
            <translation>Sigma0 a posteriori</translation>
        </message>
        <message>
            <source>Rounds</source>
            <translation>Rodadas</translation>
        </message>
        <message>
            <source>Line observations</source>
            <translation>Observações de linha</translation>
        </message>
        <message>
            <source>Tie points on roof planes</source>
            <translation>Pontos de enlace nos planos de telhado</translation>
        </message>
        <message>
            <source>Calibrates the camera-INS boresight from the images themselves, with no picked point. The
LiDAR ridge, hip and valley lines (the line table of Create LiDAR control points and lines)
are projected into every image with the trajectory, the mount and the approximate boresight.
First an angle search (coarse to fine, within Search range of the approximate boresight)
finds the boresight whose projected lines lie on the strongest image edges; then, in rounds,
sub-pixel image edges are found along every projected line (the dock's edge refinement, within
3 sigma of the projection's uncertainty) and, when tie points are given (the observation CSV
of Automatic tie points), each tie track is intersected and kept as a point-to-plane tie of
the roof plane it lies on (inside the plane's outline, from the cloud's plane ids; off the
borders; within a gate of 3 sigma of the pose and intersection uncertainty; not on a wall).
Each round runs the rigorous calibration of Boresight calibration (line and tie models,
INS priors, data snooping) and starts the next from its result, until every angle changes
by less than its standard deviation.</source>
            <translation type="vanished">Calibra o boresight câmera-INS a partir das próprias imagens, sem nenhum ponto medido. As
linhas LiDAR de cumeeira, espigão e rincão (a tabela de linhas de Criar pontos e linhas de
controle LiDAR) são projetadas em cada imagem com a trajetória, a montagem e o boresight
aproximado. Primeiro uma busca angular (do grosseiro ao fino, dentro do Intervalo de busca em
torno do boresight aproximado) encontra o boresight cujas linhas projetadas caem sobre as bordas
mais fortes da imagem; depois, em rodadas, bordas subpixel são encontradas ao longo de cada
linha projetada (o refinamento de bordas do painel, dentro de 3 sigma da incerteza da projeção)
e, quando pontos de enlace são dados (o CSV de observações de Pontos de enlace automáticos), cada
trilha é intersectada e mantida como vínculo ponto-plano do plano de telhado onde está (dentro do
contorno do plano, pelos ids de plano da nuvem; longe das bordas; dentro de uma janela de 3 sigma
da incerteza da pose e da interseção; fora de paredes). Cada rodada executa a calibração rigorosa
de Calibração de boresight (modelos de linha e de enlace, injunções do INS, data snooping) e
inicia a seguinte a partir do seu resultado, até que cada ângulo mude menos que seu desvio-padrão.</translation>
        </message>
    </context>
    <context>
        <name>lidarphoto:boresightcalibration</name>
        <message>
            <source>Boresight calibration</source>
            <translation>Calibração de boresight</translation>
        </message>
        <message>
            <source>Calibration</source>
            <translation>Calibração</translation>
        </message>
        <message>
            <source>boresight (and lever arm, interior) from LiDAR roof planes, lines and LCPs</source>
            <translation>boresight (e braço de alavanca, orientação interior) a partir de planos de telhado, linhas e LCPs do LiDAR</translation>
        </message>
        <message>
            <source>Estimates the angular misalignment (boresight) between the camera and the INS, per group of
images, from image points on roofs whose geometry comes from LiDAR: plane-constrained tie
points (a roof point in two or more images lying on its LiDAR plane), points on LiDAR
ridge/hip lines (coplanarity, one image suffices), LiDAR control points (lcp, three-plane
corners) and the single-image model of Pedrosa &amp; dos Santos (2020) (paper, its Eqs. 12-17;
needs the cloud with plane ids). INS positions and attitudes are weighted observations (the
INS grade); optionally the lever arm and the interior orientation are estimated. The
adjustment runs in a local east-north-up frame with the rigorous navigation frame of each
image. The camera may be perspective or fisheye (equidistant, equisolid-angle, orthographic,
stereographic, Brown added, as Calibrate camera writes it): every ray and collinearity goes
through its own projection.</source>
            <translation>Estima o desalinhamento angular (boresight) entre a câmera e o INS, por grupo de imagens, a
partir de pontos de imagem sobre telhados cuja geometria vem do LiDAR: pontos de enlace com
restrição de plano (um ponto de telhado em duas ou mais imagens situado sobre o seu plano
LiDAR), pontos sobre linhas de cumeeira/espigão do LiDAR (coplanaridade; uma imagem basta),
pontos de controle LiDAR (lcp, cantos de três planos) e o modelo de imagem única de Pedrosa &amp;
dos Santos (2020) (paper, suas Eqs. 12-17; requer a nuvem com os identificadores de plano). As
posições e atitudes do INS são observações ponderadas (a classe do INS); opcionalmente, o braço
de alavanca e a orientação interior são estimados. O ajustamento é feito em um referencial
local leste-norte-acima, com o referencial de navegação rigoroso de cada imagem. A câmera pode ser perspectiva ou olho de peixe (equidistante, de ângulo equissólido,
orthográfica, estereográfica, com Brown acrescentado, como Calibrar câmera a escreve): cada raio e
cada colinearidade passam pela sua própria projeção.</translation>
        </message>
        <message>
            <source>Inputs: camera JSON, trajectory CSV (as Trajectory to exterior orientation), the mount with
the initial boresight (degrees), the image observation CSV (image_id, point_id, col, row,
sigma_px, type, target_id), and the plane / line / LCP tables of Extract roof planes and
Create LiDAR control points and lines.</source>
            <translation>Entradas: JSON da câmera, CSV da trajetória (como em Trajetória para orientação exterior), a
montagem com o boresight inicial (graus), o CSV de observações de imagem (image_id, point_id,
col, row, sigma_px, type, target_id) e as tabelas de planos / linhas / LCPs de Extrair planos
de telhado e Criar pontos e linhas de controle LiDAR.</translation>
        </message>
        <message>
            <source>Surveyed ground control: rows of type control (as Locate control points writes them) measure
the point point_id of GROUND_POINTS (point_id, X, Y, Z, sx, sy, sz, role), used like an LCP
with the diagonal covariance of its sigmas; points of role check are left out of the
adjustment (their ground positions are in the residuals). A control row naming no ground
point is an error.</source>
            <translation>Controle de campo levantado: linhas do tipo control (como Localizar pontos de controle as escreve) medem
o ponto point_id de GROUND_POINTS (point_id, X, Y, Z, sx, sy, sz, role), usado como um LCP
com a covariância diagonal dos seus desvios-padrão; pontos de role check ficam fora do
ajustamento (as suas posições no terreno estão nos resíduos). Uma linha control que não nomeia
nenhum ponto de apoio é um erro.</translation>
        </message>
        <message>
            <source>Grouping: one boresight for all images, one per value of the trajectory's group column
(flight line, direction or session) or one per heading octant.</source>
            <translation>Agrupamento: um boresight para todas as imagens, um por valor da coluna de grupo da trajetória
(faixa de voo, direção ou sessão) ou um por octante de rumo.</translation>
        </message>
        <message>
            <source>Timing offset (ESTIMATE_TIMING): a constant camera timing offset dt (exposure = recorded
time + dt) as one more unknown, from the trajectory's velocities when the table has them
(v_north, v_east, v_up, as Import trajectory writes them), else from the neighbouring
exposures of each flight line. Estimated with the lever arm it needs lines flown at clearly
different speeds: with one speed dt times the speed is an along-track lever arm, and the run
is refused as not observable, naming both.</source>
            <translation>Atraso de disparo (ESTIMATE_TIMING): um atraso constante dt da câmera (exposição = tempo
registrado + dt) como mais uma incógnita, a partir das velocidades da trajetória quando a tabela
as tem (v_north, v_east, v_up, como Importar trajetória as escreve), senão das exposições
vizinhas de cada faixa de voo. Estimado junto com o braço de alavanca, exige faixas voadas a
velocidades claramente diferentes: com uma só velocidade, dt vezes a velocidade é um braço de
alavanca ao longo da faixa, e a execução é recusada como não observável, nomeando ambos.</translation>
        </message>
        <message>
            <source>Outputs: the boresight per group (CSV), the updated exterior orientation (CSV), the image
residuals (a layer at each observation's ground position, and optionally CSV) and an HTML
summary; a set-up that cannot determine the boresight is an error that names the
parameters and why (the HTML then carries the diagnosis).</source>
            <translation>Saídas: o boresight por grupo (CSV), a orientação exterior atualizada (CSV), os resíduos das
imagens (uma camada na posição no terreno de cada observação e, opcionalmente, CSV) e um resumo
HTML; uma configuração que não permite determinar o boresight é um erro que nomeia os
parâmetros e o motivo (o HTML traz então o diagnóstico).</translation>
        </message>
        <message>
            <source>## Checks of the result
The run fails (nothing but the HTML summary, which says why, is written) when the
adjustment did not converge, when its global test fails with sigma0 above the largest sigma0
(the observations do not fit their sigmas), when the robust stage and data snooping rejected
more observations than their false alarms explain (the global test of the rest then says
nothing), or when an estimated angle exceeds the largest plausible boresight. With Write the
results even when the checks fail, the outputs are written and each starts with a warning (CSV:
comment lines beginning with #).</source>
            <translation>## Verificações do resultado
A execução falha (nada é gravado além do resumo HTML, que diz o motivo) quando o ajustamento
não convergiu, quando o seu teste global falha com sigma0 acima do maior sigma0 (as observações
não se ajustam aos seus desvios-padrão), quando o estágio robusto e o data snooping rejeitaram
mais observações do que os seus falsos alarmes explicam (o teste global do restante então nada
diz), ou quando um ângulo estimado excede o maior boresight plausível. Com Gravar os resultados mesmo quando as verificações falham, as saídas são gravadas
e cada uma começa com um aviso (CSV: linhas de comentário iniciadas por #).</translation>
        </message>
        <message>
            <source>Camera (JSON)</source>
            <translation>Câmera (JSON)</translation>
        </message>
        <message>
            <source>JSON files (*.json)</source>
            <translation>Arquivos JSON (*.json)</translation>
        </message>
        <message>
            <source>Trajectory table (CSV)</source>
            <translation>Tabela da trajetória (CSV)</translation>
        </message>
        <message>
            <source>CSV files (*.csv *.txt)</source>
            <translation>Arquivos CSV (*.csv *.txt)</translation>
        </message>
        <message>
            <source>Mapping CRS</source>
            <translation>SRC de mapeamento</translation>
        </message>
        <message>
            <source>projected CRS of the trajectory and of the LiDAR tables</source>
            <translation>SRC projetado da trajetória e das tabelas LiDAR</translation>
        </message>
        <message>
            <source>Lever arm x,y,z</source>
            <translation>Braço de alavanca x,y,z</translation>
        </message>
        <message>
            <source>camera perspective centre in the INS body frame (x forward, y right, z down)</source>
            <translation>centro perspectivo da câmera no referencial do corpo do INS (x para a frente, y para a direita, z para baixo)</translation>
        </message>
        <message>
            <source>Camera mount</source>
            <translation>Montagem da câmera</translation>
        </message>
        <message>
            <source>nominal camera-to-body rotation; custom uses MOUNT_MATRIX</source>
            <translation>rotação nominal da câmera para o corpo; custom usa MOUNT_MATRIX</translation>
        </message>
        <message>
            <source>image_top_forward: image top towards the flight direction (nose)</source>
            <translation>image_top_forward: topo da imagem no sentido do voo (nariz)</translation>
        </message>
        <message>
            <source>image_right_forward: image right side towards the flight direction</source>
            <translation>image_right_forward: lado direito da imagem no sentido do voo</translation>
        </message>
        <message>
            <source>image_bottom_forward: image bottom towards the flight direction</source>
            <translation>image_bottom_forward: base da imagem no sentido do voo</translation>
        </message>
        <message>
            <source>image_left_forward: image left side towards the flight direction</source>
            <translation>image_left_forward: lado esquerdo da imagem no sentido do voo</translation>
        </message>
        <message>
            <source>custom: custom matrix (MOUNT_MATRIX)</source>
            <translation>custom: matriz definida pelo usuário (MOUNT_MATRIX)</translation>
        </message>
        <message>
            <source>Mount matrix R_c^b (9 numbers, row-major)</source>
            <translation>Matriz de montagem R_c^b (9 números, por linhas)</translation>
        </message>
        <message>
            <source>the nominal mount R_c^b when MOUNT is custom</source>
            <translation>a montagem nominal R_c^b quando MOUNT é custom</translation>
        </message>
        <message>
            <source>Boresight domega,dphi,dkappa</source>
            <translation>Boresight domega,dphi,dkappa</translation>
        </message>
        <message>
            <source>small misalignment about the camera axes x, y, z (a larger rotation belongs in MOUNT)</source>
            <translation>pequeno desalinhamento em torno dos eixos x, y, z da câmera (uma rotação maior pertence a MOUNT)</translation>
        </message>
        <message>
            <source>Image observations (CSV)</source>
            <translation>Observações de imagem (CSV)</translation>
        </message>
        <message>
            <source>Plane table (CSV)</source>
            <translation>Tabela de planos (CSV)</translation>
        </message>
        <message>
            <source>Line table (CSV)</source>
            <translation>Tabela de linhas (CSV)</translation>
        </message>
        <message>
            <source>LiDAR control point table (CSV)</source>
            <translation>Tabela de pontos de controle LiDAR (CSV)</translation>
        </message>
        <message>
            <source>Ground points (CSV)</source>
            <translation>Pontos de apoio (CSV)</translation>
        </message>
        <message>
            <source>surveyed points of the control rows: point_id, X, Y, Z, sx, sy, sz, role (control or check), in the mapping CRS</source>
            <translation>pontos levantados das linhas control: point_id, X, Y, Z, sx, sy, sz, role (control ou check), no SRC de mapeamento</translation>
        </message>
        <message>
            <source>Cloud with plane ids (LAS/LAZ, paper mode only)</source>
            <translation>Nuvem com identificadores de plano (LAS/LAZ, somente no modo paper)</translation>
        </message>
        <message>
            <source>LAS/LAZ files (*.las *.laz *.LAS *.LAZ)</source>
            <translation>Arquivos LAS/LAZ (*.las *.laz *.LAS *.LAZ)</translation>
        </message>
        <message>
            <source>Boresight groups</source>
            <translation>Grupos de boresight</translation>
        </message>
        <message>
            <source>one boresight for all images</source>
            <translation>um boresight para todas as imagens</translation>
        </message>
        <message>
            <source>one per trajectory group (flight line, direction, session)</source>
            <translation>um por grupo da trajetória (faixa de voo, direção, sessão)</translation>
        </message>
        <message>
            <source>one per heading direction (octant)</source>
            <translation>um por direção de rumo (octante)</translation>
        </message>
        <message>
            <source>Control types</source>
            <translation>Tipos de controle</translation>
        </message>
        <message>
            <source>Estimate the lever arm</source>
            <translation>Estimar o braço de alavanca</translation>
        </message>
        <message>
            <source>Estimate focal length and principal point</source>
            <translation>Estimar a distância focal e o ponto principal</translation>
        </message>
        <message>
            <source>Estimate the camera timing offset</source>
            <translation>Estimar o atraso de disparo da câmera</translation>
        </message>
        <message>
            <source>a constant dt (exposure = recorded time + dt) from the trajectory's velocities (v_north, v_east, v_up columns, as Import trajectory writes them) or from neighbouring exposures of each line; with the lever arm it needs lines at clearly different speeds</source>
            <translation>um dt constante (exposição = tempo registrado + dt) a partir das velocidades da trajetória (colunas v_north, v_east, v_up, como Importar trajetória as escreve) ou das exposições vizinhas de cada faixa; com o braço de alavanca exige faixas a velocidades claramente diferentes</translation>
        </message>
        <message>
            <source>INS grade</source>
            <translation>Classe do INS</translation>
        </message>
        <message>
            <source>Applanix POS AV 310</source>
            <translation>Applanix POS AV 310</translation>
        </message>
        <message>
            <source>custom (INS sigmas)</source>
            <translation>personalizada (sigmas do INS)</translation>
        </message>
        <message>
            <source>Custom INS sigmas: horizontal, vertical, roll/pitch, heading</source>
            <translation>Sigmas do INS personalizados: horizontal, vertical, rolagem/arfagem, rumo</translation>
        </message>
        <message>
            <source>Data snooping (Baarda)</source>
            <translation>Detecção de erros grosseiros (data snooping de Baarda)</translation>
        </message>
        <message>
            <source>Largest plausible boresight angle</source>
            <translation>Maior ângulo de boresight plausível</translation>
        </message>
        <message>
            <source>an estimated angle beyond this fails the run (wrong MOUNT, image ids or observations)</source>
            <translation>um ângulo estimado além deste faz a execução falhar (MOUNT, identificadores de imagem ou observações errados)</translation>
        </message>
        <message>
            <source>Largest sigma0 when the global test fails</source>
            <translation>Maior sigma0 quando o teste global falha</translation>
        </message>
        <message>
            <source>a failed global test with sigma0 above this fails the run (wrong sigma_px or INS grade, or blunders data snooping did not catch)</source>
            <translation>um teste global reprovado com sigma0 acima deste faz a execução falhar (sigma_px ou classe do INS errados, ou erros grosseiros que o data snooping não detectou)</translation>
        </message>
        <message>
            <source>Write the results even when the checks fail</source>
            <translation>Gravar os resultados mesmo quando as verificações falham</translation>
        </message>
        <message>
            <source>no convergence, global test beyond MAX_SIGMA0, more rejections than false alarms explain or boresight beyond MAX_BORESIGHT: write the outputs anyway, each with a warning at its top</source>
            <translation>sem convergência, teste global além de MAX_SIGMA0, mais rejeições do que os falsos alarmes explicam ou boresight além de MAX_BORESIGHT: grava as saídas mesmo assim, cada uma com um aviso no início</translation>
        </message>
        <message>
            <source>Boresight per group (CSV)</source>
            <translation>Boresight por grupo (CSV)</translation>
        </message>
        <message>
            <source>CSV files (*.csv)</source>
            <translation>Arquivos CSV (*.csv)</translation>
        </message>
        <message>
            <source>Image residuals</source>
            <translation>Resíduos das imagens</translation>
        </message>
        <message>
            <source>Image residuals (CSV)</source>
            <translation>Resíduos das imagens (CSV)</translation>
        </message>
        <message>
            <source>Updated exterior orientation (CSV)</source>
            <translation>Orientação exterior atualizada (CSV)</translation>
        </message>
        <message>
            <source>Summary (HTML)</source>
            <translation>Resumo (HTML)</translation>
        </message>
        <message>
            <source>HTML files (*.html)</source>
            <translation>Arquivos HTML (*.html)</translation>
        </message>
        <message>
            <source>Sigma0 a-posteriori</source>
            <translation>Sigma0 a posteriori</translation>
        </message>
        <message>
            <source>Camera timing offset dt (ms, NaN if not estimated)</source>
            <translation>Atraso de disparo da câmera dt (ms, NaN se não estimado)</translation>
        </message>
        <message>
            <source>Sigma of the timing offset (ms)</source>
            <translation>Desvio-padrão do atraso de disparo (ms)</translation>
        </message>
        <message>
            <source>Estimates the angular misalignment (boresight) between the camera and the INS, per group of
images, from image points on roofs whose geometry comes from LiDAR: plane-constrained tie
points (a roof point in two or more images lying on its LiDAR plane), points on LiDAR
ridge/hip lines (coplanarity, one image suffices), LiDAR control points (lcp, three-plane
corners) and the single-image model of Pedrosa &amp; dos Santos (2020) (paper, its Eqs. 12-17;
needs the cloud with plane ids). INS positions and attitudes are weighted observations (the
INS grade); optionally the lever arm and the interior orientation are estimated. The
adjustment runs in a local east-north-up frame with the rigorous navigation frame of each
image.</source>
            <translation type="vanished">Estima o desalinhamento angular (boresight) entre a câmera e o INS, por grupo de imagens, a
partir de pontos de imagem sobre telhados cuja geometria vem do LiDAR: pontos de enlace com
restrição de plano (um ponto de telhado em duas ou mais imagens situado sobre o seu plano
LiDAR), pontos sobre linhas de cumeeira/espigão do LiDAR (coplanaridade; uma imagem basta),
pontos de controle LiDAR (lcp, cantos de três planos) e o modelo de imagem única de Pedrosa &amp;
dos Santos (2020) (paper, suas Eqs. 12-17; requer a nuvem com os identificadores de plano). As
posições e atitudes do INS são observações ponderadas (a classe do INS); opcionalmente, o braço
de alavanca e a orientação interior são estimados. O ajustamento é feito em um referencial
local leste-norte-acima, com o referencial de navegação rigoroso de cada imagem.</translation>
        </message>
    </context>
    <context>
        <name>lidarphoto:bundleadjustment</name>
        <message>
            <source>Bundle adjustment with self-calibration</source>
            <translation>Ajustamento por feixes de raios com autocalibração</translation>
        </message>
        <message>
            <source>Aerotriangulation</source>
            <translation>Aerotriangulação</translation>
        </message>
        <message>
            <source>exterior orientations, object points, interior orientation and APs of a block</source>
            <translation>orientações exteriores, pontos-objeto, orientação interior e parâmetros adicionais de um bloco</translation>
        </message>
        <message>
            <source>Bundle adjustment of a block of frame images: the exterior orientation of every image, the
object points (tie, control with sigmas; check points kept out and reported), and per camera
the interior orientation (principal distance, principal point) with the additional
parameters (APs) of one family, in one rigorous least-squares adjustment in a local
east-north-up frame (results in the mapping CRS).</source>
            <translation>Ajustamento por feixes de raios de um bloco de imagens de quadro: a orientação exterior de cada
imagem, os pontos-objeto (de enlace, de controle com seus desvios-padrão; os pontos de
verificação ficam de fora e são relatados) e, por câmera, a orientação interior (distância
principal, ponto principal) com os parâmetros adicionais (PAs) de uma família, em um único
ajustamento rigoroso por mínimos quadrados em um referencial local leste-norte-acima
(resultados no SRC de mapeamento).</translation>
        </message>
        <message>
            <source>AP families (Lima, Debiasi &amp; Menezes compare them on a UAV block): lens_k1k2 (radial k1, k2),
bauer (3: radial, affinity, shear; Bauer &amp; Mueller 1972), jacobsen (4), ebner (12, orthogonal
on a 3 x 3 grid; Ebner 1976), brown (14-term polynomial; Brown 1976 as in Murai et al. 1984),
conrady_brown (physical k1 k2 k3 p1 p2); none holds the camera's own lens model. all runs every
family on the same block, writes the comparison table (mean, standard deviation and RMS of the
check-point discrepancies, sigma0, significant APs) and the outputs of the best model.</source>
            <translation>Famílias de PAs (Lima, Debiasi &amp; Menezes as comparam em um bloco de VANT): lens_k1k2 (radial
k1, k2), bauer (3: radial, afinidade, cisalhamento; Bauer &amp; Mueller 1972), jacobsen (4), ebner
(12, ortogonais em uma grade 3 x 3; Ebner 1976), brown (polinômio de 14 termos; Brown 1976 como
em Murai et al. 1984), conrady_brown (físicos k1 k2 k3 p1 p2); none mantém o modelo de lente da
própria câmera. all executa todas as famílias no mesmo bloco, grava a tabela comparativa
(média, desvio-padrão e RMS das discrepâncias nos pontos de verificação, sigma0, PAs
significativos) e as saídas do melhor modelo.</translation>
        </message>
        <message>
            <source>Inputs: camera JSON (one camera, or {"cameras": [...]} with a camera column in the EO or
observation table; perspective or fisheye: equidistant, equisolid-angle, orthographic or
stereographic with Brown added, as Calibrate camera writes it, each through its own
projection), image observations (image_id, point_id, col, row, sigma_px; a row of
type control, as Locate control points writes it, must name a ground point), ground points
(point_id, X, Y, Z, sx, sy, sz, role = control | check), optionally exterior
orientations: approximate (e.g. direct georeferencing, a few degrees and metres off), or
observed when the table has sigma columns (GNSS/INS with sigmas; lever arm and boresight
corrections can be estimated). Without orientations the images that see four or more control
points are resected and the rest of the block grows by intersection and resection.</source>
            <translation>Entradas: JSON da câmera (uma câmera, ou {"cameras": [...]} com uma coluna camera na tabela de
OE ou de observações; perspectiva ou olho de peixe: equidistante, equissólida, ortográfica ou
estereográfica com Brown somado, como Calibrar câmera a escreve, cada uma pela sua própria
projeção), observações de imagem (image_id, point_id, col, row, sigma_px; uma linha
do tipo control, como Localizar pontos de controle a escreve, deve nomear um ponto de apoio),
pontos de apoio (point_id, X, Y, Z, sx, sy, sz, role = control | check) e, opcionalmente,
orientações exteriores: aproximadas (por exemplo, do georreferenciamento direto, com alguns graus e
metros de erro) ou observadas quando a tabela tem colunas de desvio-padrão (GNSS/INS com
desvios-padrão; correções do braço de alavanca e do boresight podem ser estimadas). Sem
orientações, as imagens que veem quatro ou mais pontos de controle passam por resseção e o
restante do bloco cresce por interseção e resseção.</translation>
        </message>
        <message>
            <source>Camera timing offset (ESTIMATE_TIMING): with observed orientations, a constant dt (exposure =
recorded time + dt) as one more unknown, the observed centres being the GNSS/INS positions at
the recorded times; the velocity of each exposure from the EO table (v_north, v_east, v_up or
vx, vy, vz) or differenced from the neighbouring exposures of its group. It needs strips in
different directions or at different speeds, or ground control; estimated with the lever arm,
strips at one speed are refused as not observable, naming both. dt in ms with its sigma and
correlations: the results TIMING_OFFSET_MS and TIMING_OFFSET_STD_MS, the log and the summary.</source>
            <translation>Atraso de disparo da câmera (ESTIMATE_TIMING): com orientações observadas, um dt constante
(exposição = tempo registrado + dt) como mais uma incógnita, sendo os centros observados as
posições GNSS/INS nos tempos registrados; a velocidade de cada exposição vem da tabela de OE
(v_north, v_east, v_up ou vx, vy, vz) ou é diferenciada das exposições vizinhas do seu grupo.
Exige faixas em direções diferentes ou a velocidades diferentes, ou pontos de apoio; estimado com
o braço de alavanca, faixas a uma só velocidade são recusadas como não observáveis, nomeando
ambos. dt em ms com seu desvio-padrão e correlações: os resultados TIMING_OFFSET_MS e
TIMING_OFFSET_STD_MS, o log e o resumo.</translation>
        </message>
        <message>
            <source>Statistics: sigma0, the global chi-square test, sigmas and correlations; each AP's t-test
and |correlation| above 0.9 flagged; automatic selection drops insignificant APs one at a
time (an AP correlated with others is dropped only when a joint F-test finds them
insignificant together; a correlation alone never drops one) and says which and why.
Outliers: robust reweighting (Huber or Cauchy) then Baarda's data snooping.
Datum: control points and/or observed orientations, or a
free network (inner or minimal constraints); scale bars (measured distances with sigmas) are
observations, and with a free network they give its scale. Close-range networks: FRAME
local_m or local_mm takes the coordinates in a local engineering frame with no CRS.
Tables that cannot make a block (an image without observations, a tie point seen once,
duplicated rows, unknown images, ground points in another CRS, unconnected parts) are refused
with the file and row named.</source>
            <translation>Estatística: sigma0, o teste global qui-quadrado, sigmas e correlações; o teste t de cada PA
e |correlação| acima de 0,9 sinalizados; a seleção automática remove PAs não significativos um
por vez (um PA correlacionado com outros só é removido quando um teste F conjunto os considera
não significativos juntos; uma correlação sozinha nunca remove um) e diz qual e por quê.
Outliers: reponderação robusta (Huber ou Cauchy) seguida do data snooping de Baarda.
Datum: pontos de controle e/ou orientações observadas, ou uma
rede livre (injunções internas ou mínimas); barras de escala (distâncias medidas com sigmas) são
observações e, numa rede livre, dão a sua escala. Redes a curta distância: FRAME
local_m ou local_mm toma as coordenadas num referencial local de engenharia sem CRS.
Tabelas que não formam um bloco (uma imagem sem observações, um ponto de ligação visto uma vez,
linhas duplicadas, imagens desconhecidas, pontos de apoio em outro CRS, partes desconexas) são recusadas
com o arquivo e a linha indicados.</translation>
        </message>
        <message>
            <source>Camera (JSON; several as {"cameras": [...]})</source>
            <translation>Câmera (JSON; várias como {"cameras": [...]})</translation>
        </message>
        <message>
            <source>JSON files (*.json)</source>
            <translation>Arquivos JSON (*.json)</translation>
        </message>
        <message>
            <source>Image observations (CSV)</source>
            <translation>Observações de imagem (CSV)</translation>
        </message>
        <message>
            <source>CSV files (*.csv *.txt)</source>
            <translation>Arquivos CSV (*.csv *.txt)</translation>
        </message>
        <message>
            <source>Ground points (CSV: point_id,X,Y,Z,sx,sy,sz,role)</source>
            <translation>Pontos de apoio (CSV: point_id,X,Y,Z,sx,sy,sz,role)</translation>
        </message>
        <message>
            <source>Exterior orientation, approximate or observed (CSV)</source>
            <translation>Orientação exterior, aproximada ou observada (CSV)</translation>
        </message>
        <message>
            <source>approximate values, or observations when the sigma columns are filled</source>
            <translation>valores aproximados, ou observações quando as colunas de desvio-padrão estão preenchidas</translation>
        </message>
        <message>
            <source>EO sigmas when the table has none: X, Y, Z, omega, phi, kappa</source>
            <translation>Desvios-padrão da OE quando a tabela não os tem: X, Y, Z, omega, phi, kappa</translation>
        </message>
        <message>
            <source>makes an EO table without sigma columns (e.g. from trajectorytoeo) observations; empty: approximate values only</source>
            <translation>torna observações uma tabela de OE sem colunas de desvio-padrão (por exemplo, de trajectorytoeo); vazio: apenas valores aproximados</translation>
        </message>
        <message>
            <source>Mapping CRS</source>
            <translation>SRC de mapeamento</translation>
        </message>
        <message>
            <source>projected CRS of the ground points and exterior orientations (needed unless FRAME is a local frame, which ignores it)</source>
            <translation>CRS projetado dos pontos de apoio e das orientações exteriores (necessário, a menos que FRAME seja um referencial local, que o ignora)</translation>
        </message>
        <message>
            <source>Coordinate frame</source>
            <translation>Referencial de coordenadas</translation>
        </message>
        <message>
            <source>a local frame takes X, Y, Z and omega-phi-kappa as they are (close-range networks, calibration fields): no projection, no earth curvature; every length of the inputs (coordinates, sigmas, EO_SIGMAS, scale bars) and of the outputs is in its unit</source>
            <translation>um referencial local toma X, Y, Z e ômega-fi-capa como estão (redes a curta distância, campos de calibração): sem projeção, sem curvatura terrestre; todo comprimento das entradas (coordenadas, sigmas, EO_SIGMAS, barras de escala) e das saídas está na sua unidade</translation>
        </message>
        <message>
            <source>mapping CRS (projected, metres)</source>
            <translation>CRS de mapeamento (projetado, metros)</translation>
        </message>
        <message>
            <source>local engineering frame, metres (no CRS)</source>
            <translation>referencial local de engenharia, metros (sem CRS)</translation>
        </message>
        <message>
            <source>local engineering frame, millimetres (no CRS)</source>
            <translation>referencial local de engenharia, milímetros (sem CRS)</translation>
        </message>
        <message>
            <source>Additional parameters</source>
            <translation>Parâmetros adicionais</translation>
        </message>
        <message>
            <source>none (camera fixed)</source>
            <translation>nenhum (câmera fixa)</translation>
        </message>
        <message>
            <source>lens distortion k1, k2</source>
            <translation>distorção da lente k1, k2</translation>
        </message>
        <message>
            <source>Bauer (3)</source>
            <translation>Bauer (3)</translation>
        </message>
        <message>
            <source>Jacobsen (4)</source>
            <translation>Jacobsen (4)</translation>
        </message>
        <message>
            <source>Ebner (12)</source>
            <translation>Ebner (12)</translation>
        </message>
        <message>
            <source>Brown (14)</source>
            <translation>Brown (14)</translation>
        </message>
        <message>
            <source>Conrady-Brown k1 k2 k3 p1 p2</source>
            <translation>Conrady-Brown k1 k2 k3 p1 p2</translation>
        </message>
        <message>
            <source>all (compare every family)</source>
            <translation>todas (comparar todas as famílias)</translation>
        </message>
        <message>
            <source>Estimate principal distance and point</source>
            <translation>Estimar a distância principal e o ponto principal</translation>
        </message>
        <message>
            <source>Drop insignificant APs</source>
            <translation>Descartar PAs não significativos</translation>
        </message>
        <message>
            <source>Robust reweighting before data snooping</source>
            <translation>Reponderação robusta antes do data snooping</translation>
        </message>
        <message>
            <source>Data snooping (Baarda)</source>
            <translation>Detecção de erros grosseiros (data snooping de Baarda)</translation>
        </message>
        <message>
            <source>Datum</source>
            <translation>Referencial (datum)</translation>
        </message>
        <message>
            <source>control points / observed EO</source>
            <translation>pontos de controle / OE observada</translation>
        </message>
        <message>
            <source>free network: inner constraints</source>
            <translation>rede livre: injunções internas</translation>
        </message>
        <message>
            <source>free network: minimal constraints</source>
            <translation>rede livre: injunções mínimas</translation>
        </message>
        <message>
            <source>Scale bars / measured distances (CSV: point_a,point_b,distance,sigma)</source>
            <translation>Barras de escala / distâncias medidas (CSV: point_a,point_b,distance,sigma)</translation>
        </message>
        <message>
            <source>distances between adjusted points, observations with their sigmas (frame units); with a free-network datum they give its scale (inner constraints without the scale row, or six parameters held)</source>
            <translation>distâncias entre pontos ajustados, observações com seus sigmas (unidades do referencial); com um datum de rede livre dão a sua escala (injunções internas sem a linha de escala, ou seis parâmetros fixados)</translation>
        </message>
        <message>
            <source>Estimate lever arm and boresight corrections</source>
            <translation>Estimar correções do braço de alavanca e do boresight</translation>
        </message>
        <message>
            <source>needs observed exterior orientations</source>
            <translation>requer orientações exteriores observadas</translation>
        </message>
        <message>
            <source>Estimate the camera timing offset</source>
            <translation>Estimar o atraso de disparo da câmera</translation>
        </message>
        <message>
            <source>observed orientations taken at the recorded time, the exposure at recorded time + dt: one constant dt from the EO table's velocities (v_north, v_east, v_up or vx, vy, vz) or differenced from neighbouring exposures of each group by time; needs strips in different directions or at different speeds (or ground control); with the lever arm, different speeds</source>
            <translation>orientações observadas tomadas no tempo registrado, a exposição em tempo registrado + dt: um dt constante a partir das velocidades da tabela de OE (v_north, v_east, v_up ou vx, vy, vz) ou diferenciado das exposições vizinhas de cada grupo pelo tempo; exige faixas em direções diferentes ou a velocidades diferentes (ou pontos de apoio); com o braço de alavanca, velocidades diferentes</translation>
        </message>
        <message>
            <source>Adjusted exterior orientation (CSV)</source>
            <translation>Orientação exterior ajustada (CSV)</translation>
        </message>
        <message>
            <source>CSV files (*.csv)</source>
            <translation>Arquivos CSV (*.csv)</translation>
        </message>
        <message>
            <source>Adjusted camera (JSON)</source>
            <translation>Câmera ajustada (JSON)</translation>
        </message>
        <message>
            <source>Object points (CSV)</source>
            <translation>Pontos-objeto (CSV)</translation>
        </message>
        <message>
            <source>Object points</source>
            <translation>Pontos-objeto</translation>
        </message>
        <message>
            <source>Image residuals with w-tests (CSV)</source>
            <translation>Resíduos das imagens com testes w (CSV)</translation>
        </message>
        <message>
            <source>Check-point discrepancies (CSV)</source>
            <translation>Discrepâncias nos pontos de verificação (CSV)</translation>
        </message>
        <message>
            <source>AP model comparison (CSV)</source>
            <translation>Comparação dos modelos de PAs (CSV)</translation>
        </message>
        <message>
            <source>Adjusted scale bars with w-tests (CSV)</source>
            <translation>Barras de escala ajustadas com testes w (CSV)</translation>
        </message>
        <message>
            <source>Summary (HTML)</source>
            <translation>Resumo (HTML)</translation>
        </message>
        <message>
            <source>HTML files (*.html)</source>
            <translation>Arquivos HTML (*.html)</translation>
        </message>
        <message>
            <source>Sigma0 a-posteriori</source>
            <translation>Sigma0 a posteriori</translation>
        </message>
        <message>
            <source>Check-point RMS 3D (frame unit)</source>
            <translation>RMS 3D dos pontos de verificação (unidade do referencial)</translation>
        </message>
        <message>
            <source>AP model of the outputs</source>
            <translation>Modelo de PAs das saídas</translation>
        </message>
        <message>
            <source>Camera timing offset dt (ms, NaN if not estimated)</source>
            <translation>Atraso de disparo da câmera dt (ms, NaN se não estimado)</translation>
        </message>
        <message>
            <source>Sigma of the timing offset (ms)</source>
            <translation>Desvio-padrão do atraso de disparo (ms)</translation>
        </message>
        <message>
            <source>Inputs: camera JSON (one camera, or {"cameras": [...]} with a camera column in the EO or
observation table), image observations (image_id, point_id, col, row, sigma_px; a row of
type control, as Locate control points writes it, must name a ground point), ground points
(point_id, X, Y, Z, sx, sy, sz, role = control | check), optionally exterior
orientations: approximate (e.g. direct georeferencing, a few degrees and metres off), or
observed when the table has sigma columns (GNSS/INS with sigmas; lever arm and boresight
corrections can be estimated). Without orientations the images that see four or more control
points are resected and the rest of the block grows by intersection and resection.</source>
            <translation type="vanished">Entradas: JSON da câmera (uma câmera, ou {"cameras": [...]} com uma coluna camera na tabela de
OE ou de observações), observações de imagem (image_id, point_id, col, row, sigma_px; uma linha
do tipo control, como Localizar pontos de controle a escreve, deve nomear um ponto de apoio),
pontos de apoio (point_id, X, Y, Z, sx, sy, sz, role = control | check) e, opcionalmente,
orientações exteriores: aproximadas (por exemplo, do georreferenciamento direto, com alguns graus e
metros de erro) ou observadas quando a tabela tem colunas de desvio-padrão (GNSS/INS com
desvios-padrão; correções do braço de alavanca e do boresight podem ser estimadas). Sem
orientações, as imagens que veem quatro ou mais pontos de controle passam por resseção e o
restante do bloco cresce por interseção e resseção.</translation>
        </message>
        <message>
            <source>Statistics: sigma0, the global chi-square test, sigmas and correlations; each AP's t-test
and |correlation| above 0.9 flagged; automatic selection drops insignificant APs one at a
time (an AP correlated with others is dropped only when a joint F-test finds them
insignificant together; a correlation alone never drops one) and says which and why.
Outliers: robust reweighting (Huber or Cauchy) then Baarda's data snooping.
Datum: control points and/or observed orientations, or a
free network (inner or minimal constraints). Tables that cannot make a block (an image
without observations, a tie point seen once, duplicated rows, unknown images, ground points
in another CRS, unconnected parts) are refused with the file and row named.</source>
            <translation type="vanished">Estatísticas: sigma0, o teste global qui-quadrado, desvios-padrão e correlações; teste t de
cada PA e |correlação| acima de 0,9 marcada; a seleção automática descarta, um por vez, os PAs
não significativos (um PA correlacionado com outros só é descartado quando um teste F conjunto
os considera não significativos juntos; uma correlação sozinha nunca descarta um PA) e diz
quais e por quê. Outliers: reponderação
robusta (Huber ou Cauchy) seguida do data snooping de Baarda. Referencial (datum): pontos de
controle e/ou orientações observadas, ou uma rede livre (injunções internas ou mínimas).
Tabelas que não formam um bloco (uma imagem sem observações, um ponto de enlace visto uma só
vez, linhas repetidas, imagens desconhecidas, pontos de apoio em outro SRC, partes desconexas)
são recusadas, com o arquivo e a linha indicados.</translation>
        </message>
        <message>
            <source>projected CRS of the ground points and exterior orientations</source>
            <translation type="vanished">SRC projetado dos pontos de apoio e das orientações exteriores</translation>
        </message>
        <message>
            <source>Check-point RMS 3D (m)</source>
            <translation type="vanished">RMS 3D nos pontos de verificação (m)</translation>
        </message>
        <message>
            <source>Statistics: sigma0, the global chi-square test, sigmas and correlations; each AP's t-test
and |correlation| above 0.9 flagged; automatic selection drops insignificant APs one at a
time (an AP correlated with others is dropped only when a joint F-test finds them
insignificant together; a correlation alone never drops one) and says which and why.
Outliers: robust reweighting (Huber or Cauchy) then Baarda's data snooping. Datum: control points and/or observed orientations, or a
free network (inner or minimal constraints). Tables that cannot make a block (an image
without observations, a tie point seen once, duplicated rows, unknown images, ground points
in another CRS, unconnected parts) are refused with the file and row named.</source>
            <translation type="vanished">Estatísticas: sigma0, o teste global qui-quadrado, desvios-padrão e correlações; teste t de
cada PA e |correlação| acima de 0,9 marcada; a seleção automática descarta, um por vez, os PAs
não significativos (um PA correlacionado com outros só é descartado quando um teste F conjunto
os considera não significativos juntos; uma correlação sozinha nunca descarta um PA) e diz
quais e por quê. Outliers: reponderação
robusta (Huber ou Cauchy) seguida do data snooping de Baarda. Referencial (datum): pontos de
controle e/ou orientações observadas, ou uma rede livre (injunções internas ou mínimas).
Tabelas que não formam um bloco (uma imagem sem observações, um ponto de enlace visto uma só
vez, linhas repetidas, imagens desconhecidas, pontos de apoio em outro SRC, partes desconexas)
são recusadas, com o arquivo e a linha indicados.</translation>
        </message>
        <message>
            <source>Statistics: sigma0, the global chi-square test, sigmas and correlations; each AP's t-test
and |correlation| above 0.9 flagged; automatic selection drops insignificant or too
correlated APs one at a time and says which and why. Outliers: robust reweighting (Huber or
Cauchy) then Baarda's data snooping. Datum: control points and/or observed orientations, or a
free network (inner or minimal constraints). Tables that cannot make a block (an image
without observations, a tie point seen once, duplicated rows, unknown images, ground points
in another CRS, unconnected parts) are refused with the file and row named.</source>
            <translation type="vanished">Estatísticas: sigma0, o teste global qui-quadrado, desvios-padrão e correlações; teste t de
cada PA e |correlação| acima de 0,9 marcada; a seleção automática descarta, um por vez, os PAs
não significativos ou correlacionados demais e diz quais e por quê. Outliers: reponderação
robusta (Huber ou Cauchy) seguida do data snooping de Baarda. Referencial (datum): pontos de
controle e/ou orientações observadas, ou uma rede livre (injunções internas ou mínimas).
Tabelas que não formam um bloco (uma imagem sem observações, um ponto de enlace visto uma só
vez, linhas repetidas, imagens desconhecidas, pontos de apoio em outro SRC, partes desconexas)
são recusadas, com o arquivo e a linha indicados.</translation>
        </message>
        <message>
            <source>Drop insignificant or correlated APs</source>
            <translation type="vanished">Descartar PAs não significativos ou correlacionados</translation>
        </message>
        <message>
            <source>Inputs: camera JSON (one camera, or {"cameras": [...]} with a camera column in the EO or
observation table), image observations (image_id, point_id, col, row, sigma_px), ground
points (point_id, X, Y, Z, sx, sy, sz, role = control | check), optionally exterior
orientations: approximate (e.g. direct georeferencing, a few degrees and metres off), or
observed when the table has sigma columns (GNSS/INS with sigmas; lever arm and boresight
corrections can be estimated). Without orientations the images that see four or more control
points are resected and the rest of the block grows by intersection and resection.</source>
            <translation type="vanished">Entradas: JSON da câmera (uma câmera, ou {"cameras": [...]} com uma coluna camera na tabela de
OE ou de observações), observações de imagem (image_id, point_id, col, row, sigma_px), pontos
de apoio (point_id, X, Y, Z, sx, sy, sz, role = control | check) e, opcionalmente, orientações
exteriores: aproximadas (por exemplo, do georreferenciamento direto, com alguns graus e metros de
erro) ou observadas quando a tabela tem colunas de desvio-padrão (GNSS/INS com desvios-padrão;
correções do braço de alavanca e do boresight podem ser estimadas). Sem orientações, as imagens
que veem quatro ou mais pontos de controle passam por resseção e o restante do bloco cresce por
interseção e resseção.</translation>
        </message>
    </context>
    <context>
        <name>lidarphoto:calibratecamera</name>
        <message>
            <source>Calibrate a camera from target images</source>
            <translation>Calibrar uma câmera a partir de imagens de um alvo</translation>
        </message>
        <message>
            <source>Calibration</source>
            <translation>Calibração</translation>
        </message>
        <message>
            <source>Interior orientation and lens distortion (perspective or fisheye) from views of a planar target</source>
            <translation>Orientação interior e distorção da lente (perspectiva ou olho de peixe) a partir de vistas de um alvo plano</translation>
        </message>
        <message>
            <source>Detects a planar target in every image of a folder with OpenCV (chessboard:
findChessboardCornersSB; ChArUco: CharucoDetector; ArUco grid board: ArucoDetector with
sub-pixel corners) and calibrates the camera with the project's own least-squares adjustment:
a self-calibrating bundle with one pose per view, the interior orientation f, x0, y0 and the
Brown-Conrady coefficients k1 k2 k3 p1 p2 (any subset), for the perspective projection or a
fisheye projection (equidistant, equisolid-angle, orthographic, stereographic; Schneider,
Schwalbe &amp; Maas 2009) with the Brown correction added. LENS_MODEL opencv adjusts OpenCV's own
radial-tangential model instead (perspective): the same least-squares problem as OpenCV's
calibrateCamera with a fixed aspect ratio (on OpenCV's ChArUco views: the same focal length,
principal point and sigmas), and a camera that OpenCV and COLMAP read without conversion.</source>
            <translation>Detecta um alvo plano em cada imagem de uma pasta com o OpenCV (xadrez:
findChessboardCornersSB; ChArUco: CharucoDetector; placa em grade ArUco: ArucoDetector com
cantos subpixel) e calibra a câmera com o ajustamento por mínimos quadrados do próprio projeto:
um feixe autocalibrável com uma pose por vista, a orientação interior f, x0, y0 e os
coeficientes de Brown-Conrady k1 k2 k3 p1 p2 (qualquer subconjunto), para a projeção perspectiva ou uma
projeção olho de peixe (equidistante, de ângulo equissólido, ortográfica, estereográfica; Schneider,
Schwalbe &amp; Maas 2009) com a correção de Brown acrescentada. LENS_MODEL opencv ajusta, em vez dele, o
próprio modelo radial-tangencial do OpenCV (perspectiva): o mesmo problema de mínimos quadrados do
calibrateCamera do OpenCV com a razão de aspecto fixa (nas vistas ChArUco do OpenCV: a mesma distância
focal, o mesmo ponto principal e os mesmos desvios-padrão), e uma câmera que o OpenCV e o COLMAP leem
sem conversão.</translation>
        </message>
        <message>
            <source>Target: chessboard COLUMNS x ROWS inner corners, SPACING the square side; ChArUco COLUMNS x ROWS
squares, SPACING the square side, MARKER the marker side; ArUco grid board COLUMNS x ROWS
markers, SPACING the marker side, MARKER the gap between markers. The field is fixed (its
nominal coordinates) or free (estimated; datum: the origin corner and the end of the first row
held at their nominal coordinates, which sets the scale from the square size, and the start of
the last row held in the plane Z = 0).</source>
            <translation>Alvo: xadrez com COLUMNS x ROWS cantos internos, SPACING o lado do quadrado; ChArUco com COLUMNS x ROWS
quadrados, SPACING o lado do quadrado, MARKER o lado do marcador; placa em grade ArUco com COLUMNS x ROWS
marcadores, SPACING o lado do marcador, MARKER o espaço entre marcadores. O campo é fixo (suas
coordenadas nominais) ou livre (estimado; datum: o canto de origem e o fim da primeira linha
mantidos nas suas coordenadas nominais, o que define a escala a partir do tamanho do quadrado, e o início da
última linha mantido no plano Z = 0).</translation>
        </message>
        <message>
            <source>Outputs: the camera JSON (a fisheye camera is taken by control chips, orthorectify (and so
the orthomosaic), monoplot, the bundle adjustment (self-calibrating its lens), the resection
(from control points; its straight lines stay perspective-only) and the tie points (verified
on the camera's rays: 0.021-0.033 px from the truth, refined, on simulated fisheye blocks),
the equidistant one by the COLMAP export; the algorithms still perspective-only refuse it by
name: boresight calibration, control point location), a report JSON (sigmas, correlations,
sigma0, the t-test of every lens coefficient, per-view RMS and poses), the same as an HTML
page, and the residual table (CSV). PIXEL_SIZE only scales the millimetre values of the
camera file: the calibration itself is in pixels.</source>
            <translation>Saídas: o JSON da câmera (uma câmera olho de peixe é aceita pelos chips de controle, por
orthorectify (e assim pelo ortomosaico), por monoplot, pelo ajustamento por feixes
(autocalibrando a sua lente), pela resseção (a partir de pontos de controle; as suas retas
continuam apenas perspectivas) e pelos pontos de enlace (verificados sobre os raios da câmera:
0,021-0,033 px da verdade, refinados, em blocos olho de peixe simulados), a equidistante pela
exportação COLMAP; os algoritmos ainda apenas perspectivos a recusam pelo nome: calibração de
boresight, localização de pontos de controle), um JSON de relatório (sigmas, correlações,
sigma0, o teste t de cada coeficiente da lente, RMS e poses por vista), o mesmo como página
HTML, e a tabela de resíduos (CSV). PIXEL_SIZE apenas escala os valores em milímetros do
arquivo da câmera: a calibração em si é em pixels.</translation>
        </message>
        <message>
            <source>Target images (files or folders)</source>
            <translation>Imagens do alvo (arquivos ou pastas)</translation>
        </message>
        <message>
            <source>image files, or folders whose images are all taken</source>
            <translation>arquivos de imagem, ou pastas cujas imagens são todas tomadas</translation>
        </message>
        <message>
            <source>Target</source>
            <translation>Alvo</translation>
        </message>
        <message>
            <source>chessboard</source>
            <translation>xadrez</translation>
        </message>
        <message>
            <source>ChArUco board</source>
            <translation>placa ChArUco</translation>
        </message>
        <message>
            <source>ArUco grid board</source>
            <translation>placa em grade ArUco</translation>
        </message>
        <message>
            <source>Columns (inner corners / squares / markers)</source>
            <translation>Colunas (cantos internos / quadrados / marcadores)</translation>
        </message>
        <message>
            <source>Rows (inner corners / squares / markers)</source>
            <translation>Linhas (cantos internos / quadrados / marcadores)</translation>
        </message>
        <message>
            <source>Square side (ArUco: marker side)</source>
            <translation>Lado do quadrado (ArUco: lado do marcador)</translation>
        </message>
        <message>
            <source>ChArUco marker side / ArUco gap</source>
            <translation>Lado do marcador ChArUco / espaço ArUco</translation>
        </message>
        <message>
            <source>ArUco dictionary</source>
            <translation>Dicionário ArUco</translation>
        </message>
        <message>
            <source>Projection</source>
            <translation>Projeção</translation>
        </message>
        <message>
            <source>perspective (central)</source>
            <translation>perspectiva (central)</translation>
        </message>
        <message>
            <source>fisheye: equidistant</source>
            <translation>olho de peixe: equidistante</translation>
        </message>
        <message>
            <source>fisheye: equisolid-angle</source>
            <translation>olho de peixe: ângulo equissólido</translation>
        </message>
        <message>
            <source>fisheye: orthographic</source>
            <translation>olho de peixe: ortográfica</translation>
        </message>
        <message>
            <source>fisheye: stereographic</source>
            <translation>olho de peixe: estereográfica</translation>
        </message>
        <message>
            <source>Lens model</source>
            <translation>Modelo da lente</translation>
        </message>
        <message>
            <source>the same coefficients k1 k2 k3 p1 p2 in either direction: Brown-Conrady corrects the measured point, OpenCV's model distorts the ideal one (the camera then goes to OpenCV or COLMAP unchanged); OpenCV's model only with the perspective projection</source>
            <translation>os mesmos coeficientes k1 k2 k3 p1 p2 em um ou outro sentido: Brown-Conrady corrige o ponto medido, o modelo do OpenCV distorce o ideal (a câmera vai então para o OpenCV ou o COLMAP sem alteração); o modelo do OpenCV só com a projeção perspectiva</translation>
        </message>
        <message>
            <source>Brown-Conrady correction (photogrammetric)</source>
            <translation>correção de Brown-Conrady (fotogramétrica)</translation>
        </message>
        <message>
            <source>OpenCV / COLMAP distortion (perspective)</source>
            <translation>distorção do OpenCV / COLMAP (perspectiva)</translation>
        </message>
        <message>
            <source>Lens coefficients estimated</source>
            <translation>Coeficientes da lente estimados</translation>
        </message>
        <message>
            <source>coefficients of the lens model; the others are held at zero</source>
            <translation>coeficientes do modelo da lente; os demais ficam fixos em zero</translation>
        </message>
        <message>
            <source>Target field</source>
            <translation>Campo do alvo</translation>
        </message>
        <message>
            <source>fixed (nominal coordinates)</source>
            <translation>fixo (coordenadas nominais)</translation>
        </message>
        <message>
            <source>free (estimated, minimal datum)</source>
            <translation>livre (estimado, datum mínimo)</translation>
        </message>
        <message>
            <source>Pixel size</source>
            <translation>Tamanho do pixel</translation>
        </message>
        <message>
            <source>A-priori sigma of a detected point</source>
            <translation>Sigma a priori de um ponto detectado</translation>
        </message>
        <message>
            <source>Camera name</source>
            <translation>Nome da câmera</translation>
        </message>
        <message>
            <source>Calibrated camera (JSON)</source>
            <translation>Câmera calibrada (JSON)</translation>
        </message>
        <message>
            <source>JSON files (*.json)</source>
            <translation>Arquivos JSON (*.json)</translation>
        </message>
        <message>
            <source>Calibration report (JSON)</source>
            <translation>Relatório da calibração (JSON)</translation>
        </message>
        <message>
            <source>Calibration report (HTML)</source>
            <translation>Relatório da calibração (HTML)</translation>
        </message>
        <message>
            <source>HTML files (*.html)</source>
            <translation>Arquivos HTML (*.html)</translation>
        </message>
        <message>
            <source>Residuals per point (CSV)</source>
            <translation>Resíduos por ponto (CSV)</translation>
        </message>
        <message>
            <source>CSV files (*.csv)</source>
            <translation>Arquivos CSV (*.csv)</translation>
        </message>
        <message>
            <source>Views used</source>
            <translation>Vistas usadas</translation>
        </message>
        <message>
            <source>Target points used</source>
            <translation>Pontos do alvo usados</translation>
        </message>
        <message>
            <source>Reprojection RMS (px)</source>
            <translation>RMS de reprojeção (px)</translation>
        </message>
        <message>
            <source>Sigma0 (a-priori 1)</source>
            <translation>Sigma0 (a priori 1)</translation>
        </message>
        <message>
            <source>Focal length (px)</source>
            <translation>Distância focal (px)</translation>
        </message>
        <message>
            <source>Detects a planar target in every image of a folder with OpenCV (chessboard:
findChessboardCornersSB; ChArUco: CharucoDetector; ArUco grid board: ArucoDetector with
sub-pixel corners) and calibrates the camera with the project's own least-squares adjustment:
a self-calibrating bundle with one pose per view, the interior orientation f, x0, y0 and the
Brown-Conrady coefficients k1 k2 k3 p1 p2 (any subset), for the perspective projection or a
fisheye projection (equidistant, equisolid-angle, orthographic, stereographic; Schneider,
Schwalbe &amp; Maas 2009) with the Brown correction added.</source>
            <translation type="vanished">Detecta um alvo plano em cada imagem de uma pasta com o OpenCV (xadrez:
findChessboardCornersSB; ChArUco: CharucoDetector; placa em grade ArUco: ArucoDetector com
cantos subpixel) e calibra a câmera com o ajustamento por mínimos quadrados do próprio projeto:
um feixe autocalibrável com uma pose por vista, a orientação interior f, x0, y0 e os
coeficientes de Brown-Conrady k1 k2 k3 p1 p2 (qualquer subconjunto), para a projeção perspectiva ou uma
projeção olho de peixe (equidistante, de ângulo equissólido, ortográfica, estereográfica; Schneider,
Schwalbe &amp; Maas 2009) com a correção de Brown acrescentada.</translation>
        </message>
        <message>
            <source>Brown-Conrady coefficients; the others are held at zero</source>
            <translation type="vanished">Coeficientes de Brown-Conrady; os demais são mantidos em zero</translation>
        </message>
        <message>
            <source>Outputs: the camera JSON (a fisheye camera is taken by control chips, orthorectify (and so
the orthomosaic), monoplot, the bundle adjustment (self-calibrating its lens) and the
resection (from control points; its straight lines stay perspective-only), the equidistant
one by the COLMAP export; the algorithms still perspective-only refuse it by name: boresight
calibration, tie points, control point location), a report JSON (sigmas, correlations,
sigma0, the t-test of every lens coefficient, per-view RMS and poses), the same as an HTML
page, and the residual table (CSV). PIXEL_SIZE only scales the millimetre values of the
camera file: the calibration itself is in pixels.</source>
            <translation type="vanished">Saídas: o JSON da câmera (uma câmera olho de peixe é aceita pelos chips de controle, por
orthorectify (e assim pelo ortomosaico), por monoplot, pelo ajustamento por feixes
(autocalibrando a sua lente) e pela resseção (a partir de pontos de controle; as suas retas
continuam apenas perspectivas), a equidistante pela exportação COLMAP; os algoritmos ainda
apenas perspectivos a recusam pelo nome: calibração de boresight, pontos de enlace, localização
de pontos de controle), um JSON de relatório (sigmas, correlações, sigma0, o teste t de cada
coeficiente da lente, RMS e poses por vista), o mesmo como página HTML, e a tabela de resíduos
(CSV). PIXEL_SIZE apenas escala os valores em milímetros do arquivo da câmera: a calibração em
si é em pixels.</translation>
        </message>
        <message>
            <source>Outputs: the camera JSON (a fisheye camera is taken by control chips, orthorectify (and so
the orthomosaic) and monoplot, the equidistant one by the COLMAP export; the algorithms still
perspective-only refuse it by name: resection, bundle adjustment, boresight calibration, tie
points, control point location), a report JSON (sigmas, correlations, sigma0, the t-test of
every lens coefficient, per-view RMS and poses), the same as an HTML page, and the residual
table (CSV). PIXEL_SIZE only scales the millimetre values of the camera file: the calibration
itself is in pixels.</source>
            <translation type="vanished">Saídas: o JSON da câmera (uma câmera olho de peixe é aceita pelos chips de controle, por
orthorectify (e assim pelo ortomosaico) e por monoplot, a equidistante pela exportação COLMAP; os
algoritmos ainda apenas perspectivos a recusam pelo nome: resseção, ajustamento por feixes,
calibração de boresight, pontos de enlace, localização de pontos de controle), um JSON de
relatório (sigmas, correlações, sigma0, o teste t de cada coeficiente da lente, RMS e poses por
vista), o mesmo como página HTML, e a tabela de resíduos (CSV). PIXEL_SIZE apenas escala os
valores em milímetros do arquivo da câmera: a calibração em si é em pixels.</translation>
        </message>
        <message>
            <source>Outputs: the camera JSON (usable by every algorithm; a fisheye camera is refused by those whose
kernels are perspective-only), a report JSON (sigmas, correlations, sigma0, the t-test of every
lens coefficient, per-view RMS and poses), the same as an HTML page, and the residual table
(CSV). PIXEL_SIZE only scales
the millimetre values of the camera file: the calibration itself is in pixels.</source>
            <translation type="vanished">Saídas: o JSON da câmera (utilizável por todos os algoritmos; uma câmera olho de peixe é recusada por aqueles cujos
núcleos são apenas perspectivos), um JSON de relatório (sigmas, correlações, sigma0, o teste t de cada
coeficiente da lente, RMS e poses por vista), o mesmo como página HTML, e a tabela de resíduos
(CSV). PIXEL_SIZE apenas escala
os valores em milímetros do arquivo da câmera: a calibração em si é em pixels.</translation>
        </message>
        <message>
            <source>Photogrammetry</source>
            <translation type="vanished">Fotogrametria</translation>
        </message>
    </context>
    <context>
        <name>lidarphoto:createlcps</name>
        <message>
            <source>Create LiDAR control points and lines</source>
            <translation>Criar pontos e linhas de controle LiDAR</translation>
        </message>
        <message>
            <source>LiDAR</source>
            <translation>LiDAR</translation>
        </message>
        <message>
            <source>LiDAR control points and lines from intersecting roof planes</source>
            <translation>pontos e linhas de controle LiDAR a partir da interseção de planos de telhado</translation>
        </message>
        <message>
            <source>Intersects roof planes found by Extract roof planes: three planes meeting at a roof corner
give a LiDAR control point (LCP), two adjacent planes give a 3D line (ridge, hip, valley or
other), each with a covariance propagated from the plane fits.</source>
            <translation>Intersecta os planos de telhado encontrados por Extrair planos de telhado: três planos que se
encontram em um canto de telhado dão um ponto de controle LiDAR (LCP), dois planos adjacentes
dão uma linha 3D (cumeeira, espigão, rincão ou outra), cada um com uma covariância propagada a
partir dos ajustes dos planos.</translation>
        </message>
        <message>
            <source>Planes: the plane table CSV; Cloud: the LAS/LAZ written by the same algorithm (with its
plane_id dimension). Two planes are adjacent when their points come within delta of each
other along a common boundary at least min boundary long. A corner is kept only when every
pair of its normals differ by at least min angle, the 3x3 system is well conditioned (max
condition) and the point lies within max support distance of the points of each plane; where
more than three planes meet (a pyramid apex) the most precise triple is kept. Lines are
clipped to the common support of the two planes.</source>
            <translation>Planos: o CSV da tabela de planos; Nuvem: o LAS/LAZ gravado pelo mesmo algoritmo (com a sua
dimensão plane_id). Dois planos são adjacentes quando seus pontos chegam a menos de delta uns
dos outros ao longo de uma fronteira comum de comprimento mínimo min boundary. Um canto só é
mantido quando cada par de suas normais difere de pelo menos o ângulo mínimo, o sistema 3x3 é
bem condicionado (número de condição máximo) e o ponto está a menos da distância máxima de
suporte dos pontos de cada plano; onde mais de três planos se encontram (o ápice de uma
pirâmide), a tripla mais precisa é mantida. As linhas são recortadas ao suporte comum dos dois
planos.</translation>
        </message>
        <message>
            <source>Distances are in the cloud's CRS unit (e.g. feet for a CRS in feet) unless distance unit is
metres; the outputs are in the CRS unit. Optionally give your own plane-id triples
("1,2,3; 4,5,6") or pairs ("1,2; 2,3") instead of the automatic ones. The log counts the
rejected candidates per reason; each one, with its numbers and units, is listed only in
verbose mode (command line: -vv; QGIS: Processing options, logging level Verbose).</source>
            <translation>As distâncias estão na unidade do SRC da nuvem (por exemplo, pés para um SRC em pés), a menos que a unidade de distância seja
metros; as saídas estão na unidade do SRC. Opcionalmente, dê as suas próprias triplas de ids de planos
("1,2,3; 4,5,6") ou pares ("1,2; 2,3") em vez das automáticas. O log conta os
candidatos rejeitados por motivo; cada um, com os seus números e unidades, é listado apenas no
modo verboso (linha de comando: -vv; QGIS: opções do Processamento, nível de log Verbose).</translation>
        </message>
        <message>
            <source>Plane table (CSV)</source>
            <translation>Tabela de planos (CSV)</translation>
        </message>
        <message>
            <source>CSV files (*.csv *.txt)</source>
            <translation>Arquivos CSV (*.csv *.txt)</translation>
        </message>
        <message>
            <source>Cloud with plane ids (LAS/LAZ)</source>
            <translation>Nuvem com identificadores de plano (LAS/LAZ)</translation>
        </message>
        <message>
            <source>LAS/LAZ files (*.las *.laz *.LAS *.LAZ)</source>
            <translation>Arquivos LAS/LAZ (*.las *.laz *.LAS *.LAZ)</translation>
        </message>
        <message>
            <source>CRS (overrides the file's)</source>
            <translation>SRC (substitui o do arquivo)</translation>
        </message>
        <message>
            <source>the cloud's CRS when the file has none or a wrong one (EPSG:xxxx or WKT)</source>
            <translation>o SRC da nuvem quando o arquivo não tem nenhum ou tem um errado (EPSG:xxxx ou WKT)</translation>
        </message>
        <message>
            <source>Distance unit</source>
            <translation>Unidade de distância</translation>
        </message>
        <message>
            <source>unit of the length parameters: the cloud's CRS unit (e.g. international feet) or metres, converted</source>
            <translation>unidade dos parâmetros de comprimento: a unidade do SRC da nuvem (por exemplo, pés internacionais) ou metros, convertidos</translation>
        </message>
        <message>
            <source>cloud CRS units</source>
            <translation>unidades do SRC da nuvem</translation>
        </message>
        <message>
            <source>metres</source>
            <translation>metros</translation>
        </message>
        <message>
            <source>Adjacency distance delta</source>
            <translation>Distância de adjacência delta</translation>
        </message>
        <message>
            <source>Minimum common boundary</source>
            <translation>Fronteira comum mínima</translation>
        </message>
        <message>
            <source>Maximum distance of a corner from each plane's points</source>
            <translation>Distância máxima de um canto aos pontos de cada plano</translation>
        </message>
        <message>
            <source>Minimum angle between normals</source>
            <translation>Ângulo mínimo entre as normais</translation>
        </message>
        <message>
            <source>Maximum condition number</source>
            <translation>Número de condição máximo</translation>
        </message>
        <message>
            <source>Plane triples</source>
            <translation>Triplas de planos</translation>
        </message>
        <message>
            <source>plane ids "1,2,3; 4,5,6" (default: automatic)</source>
            <translation>identificadores de plano "1,2,3; 4,5,6" (padrão: automático)</translation>
        </message>
        <message>
            <source>Plane pairs</source>
            <translation>Pares de planos</translation>
        </message>
        <message>
            <source>plane ids "1,2; 2,3" (default: automatic)</source>
            <translation>identificadores de plano "1,2; 2,3" (padrão: automático)</translation>
        </message>
        <message>
            <source>LiDAR control points</source>
            <translation>Pontos de controle LiDAR</translation>
        </message>
        <message>
            <source>LiDAR control lines</source>
            <translation>Linhas de controle LiDAR</translation>
        </message>
        <message>
            <source>Control point table (CSV)</source>
            <translation>Tabela de pontos de controle (CSV)</translation>
        </message>
        <message>
            <source>CSV files (*.csv)</source>
            <translation>Arquivos CSV (*.csv)</translation>
        </message>
        <message>
            <source>Control line table (CSV)</source>
            <translation>Tabela de linhas de controle (CSV)</translation>
        </message>
        <message>
            <source>Plane adjacency graph (CSV)</source>
            <translation>Grafo de adjacência dos planos (CSV)</translation>
        </message>
        <message>
            <source>Number of LCPs</source>
            <translation>Número de LCPs</translation>
        </message>
        <message>
            <source>Number of lines</source>
            <translation>Número de linhas</translation>
        </message>
        <message>
            <source>Distances are in the cloud's CRS unit (e.g. feet for a CRS in feet) unless distance unit is
metres; the outputs are in the CRS unit. Optionally give your own plane-id triples
("1,2,3; 4,5,6") or pairs ("1,2; 2,3") instead of the automatic ones. Rejected candidates
are listed in the log with the reason.</source>
            <translation type="vanished">As distâncias estão na unidade do SRC da nuvem (por exemplo, pés para um SRC em pés), a menos
que a unidade de distância seja metros; as saídas estão na unidade do SRC. Opcionalmente,
informe suas próprias triplas ("1,2,3; 4,5,6") ou pares ("1,2; 2,3") de identificadores de
plano em vez dos automáticos. Os candidatos rejeitados são listados no log com o motivo.</translation>
        </message>
    </context>
    <context>
        <name>lidarphoto:exportcolmap</name>
        <message>
            <source>Export COLMAP model</source>
            <translation>Exportar modelo COLMAP</translation>
        </message>
        <message>
            <source>Aerotriangulation</source>
            <translation>Aerotriangulação</translation>
        </message>
        <message>
            <source>Cameras + exterior orientation (+ observations, points) -&gt; COLMAP text model</source>
            <translation>Câmeras + orientação exterior (+ observações, pontos) -&gt; modelo COLMAP em texto</translation>
        </message>
        <message>
            <source>Writes cameras.txt, images.txt and points3D.txt in OUTPUT_FOLDER, so a block oriented or
calibrated here continues in COLMAP (or the tools that read its models: OpenMVS, Gaussian
splatting). Cameras are written exactly: no lens (SIMPLE_PINHOLE), the forward models opencv
(OPENCV, or FULL_OPENCV with k3), opencv_full (FULL_OPENCV), and with the equidistant
projection opencv_fisheye (OPENCV_FISHEYE) and thin_prism_fisheye (THIN_PRISM_FISHEYE),
their coefficients renormalised exactly to the current focal length; a correction lens model
(brown_conrady and the other photogrammetric ones) has no exact COLMAP model and is refused
by name.</source>
            <translation>Escreve cameras.txt, images.txt e points3D.txt em OUTPUT_FOLDER, para que um bloco orientado ou
calibrado aqui continue no COLMAP (ou nas ferramentas que leem seus modelos: OpenMVS, Gaussian
splatting). As câmeras são escritas exatamente: sem lente (SIMPLE_PINHOLE), os modelos diretos opencv
(OPENCV, ou FULL_OPENCV com k3), opencv_full (FULL_OPENCV) e, com a projeção
equidistante, opencv_fisheye (OPENCV_FISHEYE) e thin_prism_fisheye (THIN_PRISM_FISHEYE),
com os coeficientes renormalizados exatamente para a distância focal atual; um modelo de lente de correção
(brown_conrady e os outros fotogramétricos) não tem modelo COLMAP exato e é recusado
pelo nome.</translation>
        </message>
        <message>
            <source>Orientations are written as COLMAP's world-to-camera quaternion and translation in the EO's
own coordinates (the mapping CRS; COLMAP stores no CRS: import it back with FRAME = that
CRS). OBSERVATIONS become each image's keypoints, tracked to the POINTS (a ground point table,
e.g. importcolmap's OUTPUT_POINTS) that share their point_id; the others are untracked.</source>
            <translation>As orientações são escritas como o quatérnio e a translação mundo-câmera do COLMAP, nas coordenadas
da própria EO (o CRS de mapeamento; o COLMAP não guarda CRS: importe de volta com FRAME = esse
CRS). As OBSERVATIONS tornam-se os pontos-chave de cada imagem, rastreados até os POINTS (uma tabela de pontos de apoio,
p. ex. a OUTPUT_POINTS do importcolmap) que compartilham o seu point_id; os demais ficam sem rastro.</translation>
        </message>
        <message>
            <source>Camera(s) (JSON)</source>
            <translation>Câmera(s) (JSON)</translation>
        </message>
        <message>
            <source>JSON files (*.json)</source>
            <translation>Arquivos JSON (*.json)</translation>
        </message>
        <message>
            <source>Exterior orientation table (CSV)</source>
            <translation>Tabela de orientação exterior (CSV)</translation>
        </message>
        <message>
            <source>CSV files (*.csv *.txt)</source>
            <translation>Arquivos CSV (*.csv *.txt)</translation>
        </message>
        <message>
            <source>Observations (CSV)</source>
            <translation>Observações (CSV)</translation>
        </message>
        <message>
            <source>3D points (ground point table, CSV)</source>
            <translation>Pontos 3D (tabela de pontos de apoio, CSV)</translation>
        </message>
        <message>
            <source>Output folder (the COLMAP model)</source>
            <translation>Pasta de saída (o modelo COLMAP)</translation>
        </message>
        <message>
            <source>Number of images</source>
            <translation>Número de imagens</translation>
        </message>
        <message>
            <source>Number of 3D points</source>
            <translation>Número de pontos 3D</translation>
        </message>
    </context>
    <context>
        <name>lidarphoto:exportopensfm</name>
        <message>
            <source>Export OpenSfM reconstruction</source>
            <translation>Exportar reconstrução OpenSfM</translation>
        </message>
        <message>
            <source>Aerotriangulation</source>
            <translation>Aerotriangulação</translation>
        </message>
        <message>
            <source>Cameras + exterior orientation (+ observations, points) -&gt; OpenSfM reconstruction</source>
            <translation>Câmeras + orientação exterior (+ observações, pontos) -&gt; reconstrução OpenSfM</translation>
        </message>
        <message>
            <source>Writes reconstruction.json (and tracks.csv with OBSERVATIONS and POINTS) in OUTPUT_FOLDER, so
a block oriented or calibrated here continues in OpenSfM or ODM. Cameras are written exactly,
with the simplest OpenSfM type that holds them: perspective (centred, square, k1 k2), brown
(k1 k2 k3 p1 p2, focal_x/y, c_x/y) for the opencv lenses, fisheye or fisheye_opencv for the
equidistant projection with opencv_fisheye; their coefficients renormalised exactly to the
current focal length. A correction lens model (brown_conrady and the other photogrammetric
ones), metashape, thin_prism_fisheye and a rational opencv_full have no exact OpenSfM camera
and are refused by name (docs/formats.md, OpenSfM export).</source>
            <translation>Escreve reconstruction.json (e tracks.csv com OBSERVATIONS e POINTS) em OUTPUT_FOLDER, para que
um bloco orientado ou calibrado aqui continue no OpenSfM ou no ODM. As câmeras são escritas
exatamente, com o tipo OpenSfM mais simples que as representa: perspective (centrada, quadrada,
k1 k2), brown (k1 k2 k3 p1 p2, focal_x/y, c_x/y) para as lentes opencv, fisheye ou fisheye_opencv
para a projeção equidistante com opencv_fisheye; seus coeficientes renormalizados exatamente para
a distância focal atual. Um modelo de lente de correção (brown_conrady e os demais
fotogramétricos), metashape, thin_prism_fisheye e um opencv_full racional não têm câmera OpenSfM
exata e são recusados pelo nome (docs/formats.md, exportação OpenSfM).</translation>
        </message>
        <message>
            <source>Shots are OpenSfM's world-to-camera axis-angle rotation and translation. With CRS (the
EO's and the points' projected CRS) they are written in OpenSfM's topocentric frame (east,
north, up at reference_lla, the mean of the centres), the rotations turned from the grid
frame through ECEF; without CRS as they are (LOCAL, no reference_lla).
OBSERVATIONS of the POINTS (same point_id) become tracks.csv.</source>
            <translation>As tomadas (shots) são a rotação eixo-ângulo mundo-câmera e a translação do OpenSfM. Com CRS (o
SRC projetado da OE e dos pontos) são escritas no referencial topocêntrico do OpenSfM (leste,
norte, acima em reference_lla, a média dos centros), as rotações levadas do referencial da
quadrícula através do ECEF; sem CRS, como estão (LOCAL, sem reference_lla).
As OBSERVATIONS dos POINTS (mesmo point_id) tornam-se tracks.csv.</translation>
        </message>
        <message>
            <source>Camera(s) (JSON)</source>
            <translation>Câmera(s) (JSON)</translation>
        </message>
        <message>
            <source>JSON files (*.json)</source>
            <translation>Arquivos JSON (*.json)</translation>
        </message>
        <message>
            <source>Exterior orientation table (CSV)</source>
            <translation>Tabela de orientação exterior (CSV)</translation>
        </message>
        <message>
            <source>CSV files (*.csv *.txt)</source>
            <translation>Arquivos CSV (*.csv *.txt)</translation>
        </message>
        <message>
            <source>Observations (CSV)</source>
            <translation>Observações (CSV)</translation>
        </message>
        <message>
            <source>3D points (ground point table, CSV)</source>
            <translation>Pontos 3D (tabela de pontos de apoio, CSV)</translation>
        </message>
        <message>
            <source>CRS of the EO</source>
            <translation>SRC da OE</translation>
        </message>
        <message>
            <source>the projected CRS of the EO and points (written topocentric with reference_lla); empty: LOCAL, written as they are</source>
            <translation>o SRC projetado da OE e dos pontos (escritos topocêntricos com reference_lla); vazio: LOCAL, escritos como estão</translation>
        </message>
        <message>
            <source>Output folder (reconstruction.json)</source>
            <translation>Pasta de saída (reconstruction.json)</translation>
        </message>
        <message>
            <source>Number of images</source>
            <translation>Número de imagens</translation>
        </message>
        <message>
            <source>Number of 3D points</source>
            <translation>Número de pontos 3D</translation>
        </message>
    </context>
    <context>
        <name>lidarphoto:extractroofplanes</name>
        <message>
            <source>Extract roof planes</source>
            <translation>Extrair planos de telhado</translation>
        </message>
        <message>
            <source>LiDAR</source>
            <translation>LiDAR</translation>
        </message>
        <message>
            <source>roof planes with their precision from a classified LAS/LAZ cloud</source>
            <translation>planos de telhado com a sua precisão a partir de uma nuvem LAS/LAZ classificada</translation>
        </message>
        <message>
            <source>Extracts roof planes from a LiDAR cloud classified by a ground filter (Pedrosa &amp; dos Santos
2020, section 2.1): for every point, RANSAC on its K nearest neighbours with tolerance
epsilon; the point is kept when the plane has the minimum support, the point lies on it and
its slope is between alpha and beta (rejects vegetation and walls). Kept points are grown into
regions (distance to the region's plane and normal angle), small regions dropped, ridge and
eave points attached to the nearest plane, coplanar neighbours merged. Each plane is fitted by
the weighted eigen method of Pathak et al. (2010) on centred coordinates, with the full
covariance of (a, b, c, d) and the standard deviation of d (Khoshelham 2016). The same points
give the same planes whatever their order, the seed or the number of threads: the RANSAC
triplets are a fixed set, not random draws.</source>
            <translation>Extrai planos de telhado de uma nuvem LiDAR classificada por um filtro de terreno (Pedrosa &amp;
dos Santos 2020, seção 2.1): para cada ponto, RANSAC sobre os seus K vizinhos mais próximos com
tolerância epsilon; o ponto é mantido quando o plano tem o suporte mínimo, o ponto está sobre
ele e a sua declividade está entre alfa e beta (rejeita vegetação e paredes). Os pontos
mantidos crescem em regiões (distância ao plano da região e ângulo da normal), regiões pequenas
são descartadas, pontos de cumeeira e de beiral são ligados ao plano mais próximo e vizinhos
coplanares são fundidos. Cada plano é ajustado pelo método de autovalores ponderado de Pathak
et al. (2010) sobre coordenadas centradas, com a covariância completa de (a, b, c, d) e o
desvio-padrão de d (Khoshelham 2016). Os mesmos pontos dão os mesmos planos qualquer que seja
a sua ordem, a semente ou o número de threads: as triplas do RANSAC são um conjunto fixo, não
sorteios aleatórios.</translation>
        </message>
        <message>
            <source>## Points
Non-ground (class != 2), the listed Classes (e.g. 6), or all points (a cloud that is already
non-ground). CRS overrides the file's CRS.</source>
            <translation>## Pontos
Não terreno (classe != 2), as Classes listadas (por exemplo, 6) ou todos os pontos (uma nuvem
que já é não terreno). SRC substitui o SRC do arquivo.</translation>
        </message>
        <message>
            <source>## Units
With Distance unit = cloud CRS units, epsilon and the outline cell are in the unit of the
cloud's CRS (international feet for Autzen); with metres they are converted. Plane
parameters, centroids, rms and sigma_d are always in the CRS unit (the UNIT output names it).</source>
            <translation>## Unidades
Com Unidade de distância = unidades do SRC da nuvem, epsilon e a célula do contorno estão na
unidade do SRC da nuvem (pés internacionais para Autzen); com metros, são convertidos. Os
parâmetros dos planos, centroides, rms e sigma_d estão sempre na unidade do SRC (a saída UNIT a
nomeia).</translation>
        </message>
        <message>
            <source>## Outputs
Plane outlines (PolygonZ, concave hull for display) with every attribute; the plane table
CSV: id, a, b, c, d (n.p + d = 0, normal up), centroid_x/y/z, n_points, rms, sigma_d,
slope_deg, aspect_deg (clockwise from grid north, downslope), and the 10 upper-triangle
covariance elements cov_aa ... cov_dd; optionally a copy of the cloud with the int32 extra
dimension plane_id (-1 = none). A cloud without roofs gives zero planes and a message, not an
error.</source>
            <translation>## Saídas
Contornos dos planos (PolygonZ, envoltória côncava para exibição) com todos os atributos; o CSV
da tabela de planos: id, a, b, c, d (n.p + d = 0, normal para cima), centroid_x/y/z, n_points,
rms, sigma_d, slope_deg, aspect_deg (no sentido horário a partir do norte da quadrícula, no
sentido do declive) e os 10 elementos do triângulo superior da covariância cov_aa ... cov_dd;
opcionalmente, uma cópia da nuvem com a dimensão extra int32 plane_id (-1 = nenhum). Uma nuvem
sem telhados dá zero planos e uma mensagem, não um erro.</translation>
        </message>
        <message>
            <source>Point cloud (LAS/LAZ)</source>
            <translation>Nuvem de pontos (LAS/LAZ)</translation>
        </message>
        <message>
            <source>LAS/LAZ files (*.las *.laz *.LAS *.LAZ)</source>
            <translation>Arquivos LAS/LAZ (*.las *.laz *.LAS *.LAZ)</translation>
        </message>
        <message>
            <source>CRS (overrides the file's)</source>
            <translation>SRC (substitui o do arquivo)</translation>
        </message>
        <message>
            <source>the cloud's CRS when the file has none or a wrong one (EPSG:xxxx or WKT)</source>
            <translation>o SRC da nuvem quando o arquivo não tem nenhum ou tem um errado (EPSG:xxxx ou WKT)</translation>
        </message>
        <message>
            <source>Distance unit</source>
            <translation>Unidade de distância</translation>
        </message>
        <message>
            <source>unit of the length parameters: the cloud's CRS unit (e.g. international feet) or metres, converted</source>
            <translation>unidade dos parâmetros de comprimento: a unidade do SRC da nuvem (por exemplo, pés internacionais) ou metros, convertidos</translation>
        </message>
        <message>
            <source>cloud CRS units</source>
            <translation>unidades do SRC da nuvem</translation>
        </message>
        <message>
            <source>metres</source>
            <translation>metros</translation>
        </message>
        <message>
            <source>Points</source>
            <translation>Pontos</translation>
        </message>
        <message>
            <source>non-ground (class != 2)</source>
            <translation>não terreno (classe != 2)</translation>
        </message>
        <message>
            <source>the classes below</source>
            <translation>as classes abaixo</translation>
        </message>
        <message>
            <source>all</source>
            <translation>todos</translation>
        </message>
        <message>
            <source>Classes (e.g. 6)</source>
            <translation>Classes (por exemplo, 6)</translation>
        </message>
        <message>
            <source>LAS classes searched when POINTS is classes, e.g. 6 or 1,6</source>
            <translation>classes LAS pesquisadas quando POINTS é classes, por exemplo, 6 ou 1,6</translation>
        </message>
        <message>
            <source>Neighbours K of the local RANSAC</source>
            <translation>Vizinhos K do RANSAC local</translation>
        </message>
        <message>
            <source>Point-to-plane tolerance epsilon</source>
            <translation>Tolerância ponto-plano epsilon</translation>
        </message>
        <message>
            <source>Minimum support of a local plane</source>
            <translation>Suporte mínimo de um plano local</translation>
        </message>
        <message>
            <source>RANSAC triplets per point</source>
            <translation>Triplas do RANSAC por ponto</translation>
        </message>
        <message>
            <source>Minimum slope alpha</source>
            <translation>Declividade mínima alfa</translation>
        </message>
        <message>
            <source>Maximum slope beta</source>
            <translation>Declividade máxima beta</translation>
        </message>
        <message>
            <source>Normal angle tolerance</source>
            <translation>Tolerância do ângulo das normais</translation>
        </message>
        <message>
            <source>Minimum points per plane</source>
            <translation>Mínimo de pontos por plano</translation>
        </message>
        <message>
            <source>Outline raster cell (0 = auto)</source>
            <translation>Célula do raster de contorno (0 = automática)</translation>
        </message>
        <message>
            <source>Random seed</source>
            <translation>Semente aleatória</translation>
        </message>
        <message>
            <source>no effect, kept for scripts and models that give it: the RANSAC triplets are a fixed set, every seed gives the same planes</source>
            <translation>sem efeito, mantido para scripts e modelos que o informam: as triplas do RANSAC são um conjunto fixo, qualquer semente dá os mesmos planos</translation>
        </message>
        <message>
            <source>Roof planes</source>
            <translation>Planos de telhado</translation>
        </message>
        <message>
            <source>Plane table (CSV)</source>
            <translation>Tabela de planos (CSV)</translation>
        </message>
        <message>
            <source>CSV files (*.csv)</source>
            <translation>Arquivos CSV (*.csv)</translation>
        </message>
        <message>
            <source>Point cloud with plane_id</source>
            <translation>Nuvem de pontos com plane_id</translation>
        </message>
        <message>
            <source>LAZ files (*.laz);;LAS files (*.las)</source>
            <translation>Arquivos LAZ (*.laz);;Arquivos LAS (*.las)</translation>
        </message>
        <message>
            <source>Number of planes</source>
            <translation>Número de planos</translation>
        </message>
        <message>
            <source>Unit of the lengths</source>
            <translation>Unidade dos comprimentos</translation>
        </message>
    </context>
    <context>
        <name>lidarphoto:extracttlstargets</name>
        <message>
            <source>Extract TLS targets from scans</source>
            <translation>Extrair alvos TLS das varreduras</translation>
        </message>
        <message>
            <source>Laser scanning</source>
            <translation>Varredura a laser</translation>
        </message>
        <message>
            <source>sphere or checkerboard target centres with covariance from laser scans</source>
            <translation>centros de alvos esféricos ou em tabuleiro de xadrez, com covariância, a partir de varreduras laser</translation>
        </message>
        <message>
            <source>Finds the targets in each scan and writes their centres in the scanner frame with their
3 x 3 covariance: the observation table of TLS registration and self-calibration.</source>
            <translation>Encontra os alvos em cada varredura e grava os seus centros no referencial do escâner com a sua
covariância 3 x 3: a tabela de observações do registro e da autocalibração TLS.</translation>
        </message>
        <message>
            <source>Scans: one station per file (LAS/LAZ, PLY, or E57 with the optional pye57 package), points
in the scanner's own frame in metres (the scanner at the origin, as exported for a single
station, not registered); the station id is the file name without its suffix.</source>
            <translation>Varreduras: uma estação por arquivo (LAS/LAZ, PLY, ou E57 com o pacote opcional pye57), pontos
no referencial próprio do escâner em metros (o escâner na origem, como exportado para uma
estação isolada, não registrada); o identificador da estação é o nome do arquivo sem a
extensão.</translation>
        </message>
        <message>
            <source>Spheres of a known radius: every point votes for the centre along its normal, the peaks are
verified by RANSAC (Fischler &amp; Bolles 1981) and a least-squares fit with each point's
covariance (range along the beam, angles across it). Checkerboards (2 x 2 pattern of a known
half size): RANSAC plane and a least-squares fit of the intensity pattern; their reported
sigma is 2-3 times optimistic on simulations (the centre itself within 0.5 mm).</source>
            <translation>Esferas de raio conhecido: cada ponto vota no centro ao longo da sua normal, os picos são
verificados por RANSAC (Fischler &amp; Bolles 1981) e por um ajuste por mínimos quadrados com a
covariância de cada ponto (distância ao longo do feixe, ângulos transversais a ele). Tabuleiros
de xadrez (padrão 2 x 2 de meio lado conhecido): plano por RANSAC e ajuste por mínimos
quadrados do padrão de intensidade; o desvio-padrão relatado é 2-3 vezes otimista em simulações
(o próprio centro a menos de 0,5 mm).</translation>
        </message>
        <message>
            <source>Ids: targets are matched between scans by their mutual distances (a rigid motion keeps them),
and take the ids of CONTROL points when given (matched the same way).</source>
            <translation>Identificadores: os alvos são associados entre varreduras pelas suas distâncias mútuas (um
movimento rígido as preserva) e recebem os identificadores dos pontos de CONTROLE quando
informados (associados da mesma maneira).</translation>
        </message>
        <message>
            <source>Scans (LAS/LAZ, PLY, E57; one station per file)</source>
            <translation>Varreduras (LAS/LAZ, PLY, E57; uma estação por arquivo)</translation>
        </message>
        <message>
            <source>Target kind</source>
            <translation>Tipo de alvo</translation>
        </message>
        <message>
            <source>Sphere radius</source>
            <translation>Raio da esfera</translation>
        </message>
        <message>
            <source>Checkerboard half size</source>
            <translation>Meio lado do tabuleiro de xadrez</translation>
        </message>
        <message>
            <source>Scan point noise: range, angle</source>
            <translation>Ruído dos pontos da varredura: distância, ângulo</translation>
        </message>
        <message>
            <source>Distance tolerance of the matching</source>
            <translation>Tolerância de distância da associação</translation>
        </message>
        <message>
            <source>Control targets (CSV, for their ids)</source>
            <translation>Alvos de controle (CSV, para os seus identificadores)</translation>
        </message>
        <message>
            <source>CSV files (*.csv *.txt)</source>
            <translation>Arquivos CSV (*.csv *.txt)</translation>
        </message>
        <message>
            <source>Target observations (CSV)</source>
            <translation>Observações dos alvos (CSV)</translation>
        </message>
        <message>
            <source>CSV files (*.csv)</source>
            <translation>Arquivos CSV (*.csv)</translation>
        </message>
        <message>
            <source>Target centres found (all scans)</source>
            <translation>Centros de alvos encontrados (todas as varreduras)</translation>
        </message>
        <message>
            <source>Calibration</source>
            <translation type="vanished">Calibração</translation>
        </message>
    </context>
    <context>
        <name>lidarphoto:groundfilter</name>
        <message>
            <source>Ground filter (SMRF, PMF, cloth simulation)</source>
            <translation>Filtro de terreno (SMRF, PMF, simulação de tecido)</translation>
        </message>
        <message>
            <source>LiDAR</source>
            <translation>LiDAR</translation>
        </message>
        <message>
            <source>ground filter of a LAS/LAZ cloud: SMRF, PMF or cloth simulation</source>
            <translation>filtro de terreno de uma nuvem LAS/LAZ: SMRF, PMF ou simulação de tecido</translation>
        </message>
        <message>
            <source>Separates ground from objects. Low outliers are removed first (class 7); only last returns
can be ground when the file has return numbers. Methods:</source>
            <translation>Separa o terreno dos objetos. Os outliers baixos são removidos primeiro (classe 7); apenas os
últimos retornos podem ser terreno quando o arquivo tem números de retorno. Métodos:</translation>
        </message>
        <message>
            <source>- smrf (default): the Simple Morphological Filter of Pingel et al. (2013): openings of the
  lowest-point grid with disks of growing radius, a threshold growing with the radius
  (slope x radius), then each point within a slope-dependent tolerance of the ground surface
  is ground. The defaults are the published ones (cell 1 m, slope 0.15, window radius 18 m,
  scalar 1.25) except the final tolerance SMRF_THRESHOLD, 0.3 m instead of 0.5 m (chosen on
  AHN3, README). SMRF_SLOPE 0 estimates the terrain slope from the cloud (a first pass on
  cells twice as large; the 90th percentile of its ground slope, within 0.1-0.7); it
  over-estimates where vegetation covers steep slopes.
- pmf: the Progressive Morphological Filter of Zhang et al. (2003), with SMRF's final test.
- csf: the cloth simulation filter of Zhang et al. (2016): a cloth dropped on the cloud
  turned upside down; points within CSF_THRESHOLD of it are ground.</source>
            <translation>- smrf (padrão): o Filtro Morfológico Simples de Pingel et al. (2013): aberturas da grade de
  pontos mais baixos com discos de raio crescente, um limiar que cresce com o raio (declividade
  x raio); em seguida, cada ponto dentro de uma tolerância, dependente da declividade, da
  superfície do terreno é terreno. Os valores padrão são os publicados (célula 1 m, declividade
  0,15, raio da janela 18 m, escalar 1,25), exceto a tolerância final SMRF_THRESHOLD, 0,3 m em
  vez de 0,5 m (escolhida no AHN3, README). SMRF_SLOPE 0 estima a declividade do terreno a
  partir da nuvem (uma primeira passada em células duas vezes maiores; o percentil 90 da
  declividade do seu terreno, entre 0,1 e 0,7); superestima onde a vegetação cobre encostas
  íngremes.
- pmf: o Filtro Morfológico Progressivo de Zhang et al. (2003), com o teste final do SMRF.
- csf: o filtro de simulação de tecido de Zhang et al. (2016): um tecido lançado sobre a nuvem
  virada de cabeça para baixo; os pontos a menos de CSF_THRESHOLD dele são terreno.</translation>
        </message>
        <message>
            <source>A parameter of another method than METHOD must keep its default (it would be ignored).</source>
            <translation>Um parâmetro de um método diferente de METHOD deve manter o seu valor padrão (seria ignorado).</translation>
        </message>
        <message>
            <source>## Units
With Distance unit = cloud CRS units, every length is in the unit of the cloud's CRS (e.g.
international feet for Autzen); with metres, they are converted. The log and the UNIT output
say which unit was used. CRS overrides the file's CRS (needed when the file has none).</source>
            <translation>## Unidades
Com Unidade de distância = unidades do SRC da nuvem, todo comprimento está na unidade do SRC da
nuvem (por exemplo, pés internacionais para Autzen); com metros, eles são convertidos. O log e
a saída UNIT dizem qual unidade foi usada. SRC substitui o SRC do arquivo (necessário quando o
arquivo não tem nenhum).</translation>
        </message>
        <message>
            <source>## Outputs
A copy of the cloud (LAS/LAZ by suffix) with every original dimension and VLR, class 2 for
ground (other classes kept, or set to 1), in the same point format; with Height above ground
also the extra dimension height_above_ground (float32); optionally the DTM as GeoTIFF.</source>
            <translation>## Saídas
Uma cópia da nuvem (LAS/LAZ conforme a extensão) com todas as dimensões e VLRs originais,
classe 2 para o terreno (as outras classes mantidas, ou definidas como 1), no mesmo formato de
ponto; com Altura acima do terreno, também a dimensão extra height_above_ground (float32);
opcionalmente, o MDT em GeoTIFF.</translation>
        </message>
        <message>
            <source>Point cloud (LAS/LAZ)</source>
            <translation>Nuvem de pontos (LAS/LAZ)</translation>
        </message>
        <message>
            <source>LAS/LAZ files (*.las *.laz *.LAS *.LAZ)</source>
            <translation>Arquivos LAS/LAZ (*.las *.laz *.LAS *.LAZ)</translation>
        </message>
        <message>
            <source>CRS (overrides the file's)</source>
            <translation>SRC (substitui o do arquivo)</translation>
        </message>
        <message>
            <source>the cloud's CRS when the file has none or a wrong one (EPSG:xxxx or WKT)</source>
            <translation>o SRC da nuvem quando o arquivo não tem nenhum ou tem um errado (EPSG:xxxx ou WKT)</translation>
        </message>
        <message>
            <source>Distance unit</source>
            <translation>Unidade de distância</translation>
        </message>
        <message>
            <source>unit of the length parameters: the cloud's CRS unit (e.g. international feet) or metres, converted</source>
            <translation>unidade dos parâmetros de comprimento: a unidade do SRC da nuvem (por exemplo, pés internacionais) ou metros, convertidos</translation>
        </message>
        <message>
            <source>cloud CRS units</source>
            <translation>unidades do SRC da nuvem</translation>
        </message>
        <message>
            <source>metres</source>
            <translation>metros</translation>
        </message>
        <message>
            <source>Method</source>
            <translation>Método</translation>
        </message>
        <message>
            <source>SMRF (Pingel et al. 2013)</source>
            <translation>SMRF (Pingel et al. 2013)</translation>
        </message>
        <message>
            <source>PMF (Zhang et al. 2003)</source>
            <translation>PMF (Zhang et al. 2003)</translation>
        </message>
        <message>
            <source>cloth simulation (Zhang et al. 2016)</source>
            <translation>simulação de tecido (Zhang et al. 2016)</translation>
        </message>
        <message>
            <source>SMRF cell size</source>
            <translation>Tamanho da célula do SMRF</translation>
        </message>
        <message>
            <source>SMRF terrain slope (0 = estimated from the cloud)</source>
            <translation>Declividade do terreno do SMRF (0 = estimada a partir da nuvem)</translation>
        </message>
        <message>
            <source>SMRF largest window radius</source>
            <translation>Maior raio de janela do SMRF</translation>
        </message>
        <message>
            <source>SMRF final height tolerance</source>
            <translation>Tolerância final de altura do SMRF</translation>
        </message>
        <message>
            <source>SMRF tolerance added per unit of slope</source>
            <translation>Tolerância do SMRF acrescida por unidade de declividade</translation>
        </message>
        <message>
            <source>PMF cell size</source>
            <translation>Tamanho da célula do PMF</translation>
        </message>
        <message>
            <source>PMF maximum window size</source>
            <translation>Tamanho máximo da janela do PMF</translation>
        </message>
        <message>
            <source>PMF terrain slope</source>
            <translation>Declividade do terreno do PMF</translation>
        </message>
        <message>
            <source>PMF initial elevation threshold</source>
            <translation>Limiar inicial de elevação do PMF</translation>
        </message>
        <message>
            <source>PMF maximum elevation threshold</source>
            <translation>Limiar máximo de elevação do PMF</translation>
        </message>
        <message>
            <source>PMF window growth base b</source>
            <translation>Base b do crescimento da janela do PMF</translation>
        </message>
        <message>
            <source>PMF final height tolerance</source>
            <translation>Tolerância final de altura do PMF</translation>
        </message>
        <message>
            <source>PMF tolerance added per unit of slope</source>
            <translation>Tolerância do PMF acrescida por unidade de declividade</translation>
        </message>
        <message>
            <source>CSF cloth resolution</source>
            <translation>Resolução do tecido do CSF</translation>
        </message>
        <message>
            <source>CSF rigidness (1 steep, 2 terraces, 3 flat)</source>
            <translation>Rigidez do CSF (1 íngreme, 2 terraços, 3 plano)</translation>
        </message>
        <message>
            <source>CSF distance to the cloth</source>
            <translation>Distância ao tecido do CSF</translation>
        </message>
        <message>
            <source>CSF time step</source>
            <translation>Passo de tempo do CSF</translation>
        </message>
        <message>
            <source>CSF largest number of steps</source>
            <translation>Maior número de passos do CSF</translation>
        </message>
        <message>
            <source>Low outlier depth (0 = off)</source>
            <translation>Profundidade dos outliers baixos (0 = desligado)</translation>
        </message>
        <message>
            <source>Low outlier radius</source>
            <translation>Raio dos outliers baixos</translation>
        </message>
        <message>
            <source>PMF window growth</source>
            <translation>Crescimento da janela do PMF</translation>
        </message>
        <message>
            <source>PMF window shape</source>
            <translation>Forma da janela do PMF</translation>
        </message>
        <message>
            <source>CSF slope smoothing</source>
            <translation>Suavização de encostas do CSF</translation>
        </message>
        <message>
            <source>Only last returns can be ground</source>
            <translation>Apenas os últimos retornos podem ser terreno</translation>
        </message>
        <message>
            <source>Non-ground points</source>
            <translation>Pontos não terreno</translation>
        </message>
        <message>
            <source>keep their class</source>
            <translation>manter a sua classe</translation>
        </message>
        <message>
            <source>set to 1 (unclassified)</source>
            <translation>definir como 1 (não classificado)</translation>
        </message>
        <message>
            <source>Add the height above the DTM to the cloud</source>
            <translation>Adicionar à nuvem a altura acima do MDT</translation>
        </message>
        <message>
            <source>the extra dimension height_above_ground (float32, vertical unit); it changes the point format (extra bytes) and makes the file larger</source>
            <translation>a dimensão extra height_above_ground (float32, unidade vertical); altera o formato de ponto (bytes extras) e torna o arquivo maior</translation>
        </message>
        <message>
            <source>Classified point cloud</source>
            <translation>Nuvem de pontos classificada</translation>
        </message>
        <message>
            <source>LAZ files (*.laz);;LAS files (*.las)</source>
            <translation>Arquivos LAZ (*.laz);;Arquivos LAS (*.las)</translation>
        </message>
        <message>
            <source>DTM</source>
            <translation>MDT</translation>
        </message>
        <message>
            <source>Number of points</source>
            <translation>Número de pontos</translation>
        </message>
        <message>
            <source>Number of ground points</source>
            <translation>Número de pontos de terreno</translation>
        </message>
        <message>
            <source>Number of low outliers</source>
            <translation>Número de outliers baixos</translation>
        </message>
        <message>
            <source>Unit of the distances</source>
            <translation>Unidade das distâncias</translation>
        </message>
    </context>
    <context>
        <name>lidarphoto:importcolmap</name>
        <message>
            <source>Import COLMAP model</source>
            <translation>Importar modelo COLMAP</translation>
        </message>
        <message>
            <source>Aerotriangulation</source>
            <translation>Aerotriangulação</translation>
        </message>
        <message>
            <source>COLMAP sparse model (text or binary) -&gt; cameras, orientations, tie points</source>
            <translation>Modelo esparso COLMAP (texto ou binário) -&gt; câmeras, orientações, pontos de ligação</translation>
        </message>
        <message>
            <source>Reads a COLMAP sparse model (cameras, images and points3D, as text or binary files) and
writes the project's camera JSON, exterior orientation, observation table and points, with
the lens models converted exactly: COLMAP's distortion maps ideal to measured coordinates,
and each camera gets the forward lens model with COLMAP's own coefficients (docs/formats.md,
COLMAP). SIMPLE_PINHOLE, PINHOLE, SIMPLE_RADIAL, RADIAL, OPENCV, FULL_OPENCV,
OPENCV_FISHEYE, SIMPLE_RADIAL_FISHEYE, RADIAL_FISHEYE and THIN_PRISM_FISHEYE are supported;
FOV and RAD_TAN_THIN_PRISM_FISHEYE are refused by name.</source>
            <translation>Lê um modelo esparso COLMAP (cameras, images e points3D, como arquivos de texto ou binários) e
escreve o JSON de câmera do projeto, a orientação exterior, a tabela de observações e os pontos, com
os modelos de lente convertidos exatamente: a distorção do COLMAP leva coordenadas ideais a medidas,
e cada câmera recebe o modelo de lente direto com os próprios coeficientes do COLMAP (docs/formats.md,
COLMAP). SIMPLE_PINHOLE, PINHOLE, SIMPLE_RADIAL, RADIAL, OPENCV, FULL_OPENCV,
OPENCV_FISHEYE, SIMPLE_RADIAL_FISHEYE, RADIAL_FISHEYE e THIN_PRISM_FISHEYE são aceitos;
FOV e RAD_TAN_THIN_PRISM_FISHEYE são recusados pelo nome.</translation>
        </message>
        <message>
            <source>## Frame
A COLMAP model has no coordinate reference system: FRAME states it, and a model without one
is refused. LOCAL: the coordinates as they are (no CRS); ECEF (as COLMAP's model aligner
writes it): converted into the mapping CRS given as CRS; or the CRS the coordinates are in
(e.g. EPSG:32723: easting, northing, height). SIMILARITY (s qw qx qy qz tx ty tz) is applied
first, model -&gt; frame (X' = s R(q) X + t).</source>
            <translation>## Referencial
Um modelo COLMAP não tem sistema de referência de coordenadas: FRAME o declara, e um modelo sem ele
é recusado. LOCAL: as coordenadas como estão (sem CRS); ECEF (como o alinhador de modelos do COLMAP
o escreve): convertidas para o CRS de mapeamento dado em CRS; ou o CRS em que as coordenadas estão
(p. ex. EPSG:32723: este, norte, altitude). SIMILARITY (s qw qx qy qz tx ty tz) é aplicada
primeiro, modelo -&gt; referencial (X' = s R(q) X + t).</translation>
        </message>
        <message>
            <source>## Inputs
INPUT: the model's cameras.txt or cameras.bin (or its folder); images and points3D are read
beside it. PIXEL_SIZE: COLMAP has none; it scales the millimetres, never the projection.</source>
            <translation>## Entradas
INPUT: o cameras.txt ou cameras.bin do modelo (ou a sua pasta); images e points3D são lidos
ao lado. PIXEL_SIZE: o COLMAP não tem; ele escala os milímetros, nunca a projeção.</translation>
        </message>
        <message>
            <source>## Outputs
OUTPUT_CAMERA: the cameras (colmap_&lt;id&gt;); OUTPUT_EO: one row per registered image (image_id =
COLMAP's image name, with a camera column when there are several); OUTPUT_OBSERVATIONS: the
tracked keypoints as tie rows (point_id = COLMAP's 3D point id); OUTPUT_POINTS: the 3D points
as a ground point table with role check (triangulated tie points, never control).</source>
            <translation>## Saídas
OUTPUT_CAMERA: as câmeras (colmap_&lt;id&gt;); OUTPUT_EO: uma linha por imagem registrada (image_id =
o nome da imagem no COLMAP, com uma coluna de câmera quando há várias); OUTPUT_OBSERVATIONS: os
pontos-chave rastreados como linhas tie (point_id = o id do ponto 3D no COLMAP); OUTPUT_POINTS: os pontos 3D
como tabela de pontos de apoio com papel check (pontos de ligação triangulados, nunca controle).</translation>
        </message>
        <message>
            <source>COLMAP model (cameras.txt or cameras.bin)</source>
            <translation>Modelo COLMAP (cameras.txt ou cameras.bin)</translation>
        </message>
        <message>
            <source>COLMAP cameras (cameras.txt cameras.bin);;All files (*)</source>
            <translation>Câmeras COLMAP (cameras.txt cameras.bin);;Todos os arquivos (*)</translation>
        </message>
        <message>
            <source>Frame of the model's coordinates</source>
            <translation>Referencial das coordenadas do modelo</translation>
        </message>
        <message>
            <source>LOCAL, ECEF (with CRS) or a CRS (EPSG code or WKT); required</source>
            <translation>LOCAL, ECEF (com CRS) ou um CRS (código EPSG ou WKT); obrigatório</translation>
        </message>
        <message>
            <source>Mapping CRS (for ECEF)</source>
            <translation>CRS de mapeamento (para ECEF)</translation>
        </message>
        <message>
            <source>the projected CRS an ECEF model is converted to</source>
            <translation>o CRS projetado para o qual um modelo ECEF é convertido</translation>
        </message>
        <message>
            <source>Similarity model -&gt; frame</source>
            <translation>Semelhança modelo -&gt; referencial</translation>
        </message>
        <message>
            <source>s qw qx qy qz tx ty tz (X' = s R(q) X + t); empty: none</source>
            <translation>s qw qx qy qz tx ty tz (X' = s R(q) X + t); vazio: nenhuma</translation>
        </message>
        <message>
            <source>Pixel size</source>
            <translation>Tamanho do pixel</translation>
        </message>
        <message>
            <source>COLMAP stores none: it sets the millimetres of the camera</source>
            <translation>o COLMAP não guarda: define os milímetros da câmera</translation>
        </message>
        <message>
            <source>Cameras (JSON)</source>
            <translation>Câmeras (JSON)</translation>
        </message>
        <message>
            <source>JSON files (*.json)</source>
            <translation>Arquivos JSON (*.json)</translation>
        </message>
        <message>
            <source>Exterior orientation table (CSV)</source>
            <translation>Tabela de orientação exterior (CSV)</translation>
        </message>
        <message>
            <source>CSV files (*.csv)</source>
            <translation>Arquivos CSV (*.csv)</translation>
        </message>
        <message>
            <source>Observations (tie points, CSV)</source>
            <translation>Observações (pontos de ligação, CSV)</translation>
        </message>
        <message>
            <source>3D points (ground point table, CSV)</source>
            <translation>Pontos 3D (tabela de pontos de apoio, CSV)</translation>
        </message>
        <message>
            <source>Number of registered images</source>
            <translation>Número de imagens registradas</translation>
        </message>
        <message>
            <source>Number of cameras</source>
            <translation>Número de câmeras</translation>
        </message>
        <message>
            <source>Number of 3D points</source>
            <translation>Número de pontos 3D</translation>
        </message>
    </context>
    <context>
        <name>lidarphoto:importmetashape</name>
        <message>
            <source>Import Agisoft Metashape cameras (XML)</source>
            <translation>Importar câmeras do Agisoft Metashape (XML)</translation>
        </message>
        <message>
            <source>Aerotriangulation</source>
            <translation>Aerotriangulação</translation>
        </message>
        <message>
            <source>Metashape camera XML -&gt; cameras (exact lens model), orientations, markers</source>
            <translation>XML de câmeras do Metashape -&gt; câmeras (modelo de lente exato), orientações, marcadores</translation>
        </message>
        <message>
            <source>Reads the camera file Agisoft Metashape writes with File &gt; Export &gt; Export Cameras (Agisoft
XML) and writes the project's camera JSON, exterior orientation and markers, with the lens model
converted exactly: each calibrated sensor gets the forward lens model of Metashape's own
equations and coefficients (f, cx, cy, k1-k4, p1, p2, b1, b2; docs/formats.md, Metashape).
Frame and fisheye sensors are supported; spherical, cylindrical and RPC sensors and nonzero
p3, p4 are refused by name.</source>
            <translation>Lê o arquivo de câmeras que o Agisoft Metashape escreve com File &gt; Export &gt; Export Cameras
(Agisoft XML) e escreve o JSON de câmera, a orientação exterior e os marcadores do projeto, com o
modelo de lente convertido exatamente: cada sensor calibrado recebe o modelo de lente direto das
equações e coeficientes do próprio Metashape (f, cx, cy, k1-k4, p1, p2, b1, b2; docs/formats.md,
Metashape). Sensores de quadro e olho de peixe são aceitos; sensores esféricos, cilíndricos e RPC
e p3, p4 não nulos são recusados pelo nome.</translation>
        </message>
        <message>
            <source>## Frame
The chunk's transform (Metashape 2: each component's) takes the cameras to the chunk's
CRS: geocentric (ECEF) for a geographic or projected CRS, converted into CRS (empty: the
chunk's CRS when it is projected; a geographic chunk needs one, e.g. its UTM zone); local
coordinates (LOCAL_CS) stay as they are (LOCAL, no CRS; CRS must be empty).</source>
            <translation>## Referencial
A transformação do chunk (Metashape 2: a de cada componente) leva as câmeras ao SRC do
chunk: geocêntrico (ECEF) para um SRC geográfico ou projetado, convertido para CRS (vazio: o
SRC do chunk quando é projetado; um chunk geográfico precisa de um, p. ex. seu fuso UTM);
coordenadas locais (LOCAL_CS) ficam como estão (LOCAL, sem SRC; CRS deve ficar vazio).</translation>
        </message>
        <message>
            <source>## Skipped cameras
A camera without a transform (not aligned), whose sensor is missing or uncalibrated, or in a
component without a transform, is skipped and named in the log; so are the cameras of the
components other than the active one of a local chunk (their frames differ).</source>
            <translation>## Câmeras ignoradas
Uma câmera sem transformação (não alinhada), cujo sensor falta ou não está calibrado, ou em um
componente sem transformação, é ignorada e nomeada no log; assim também as câmeras dos
componentes que não o ativo de um chunk local (seus referenciais diferem).</translation>
        </message>
        <message>
            <source>## Outputs
OUTPUT_CAMERA: the cameras (metashape_&lt;sensor id&gt;); OUTPUT_EO: one row per imported camera
(image_id = the camera's label, or its file name with IMAGE_NAMES file; with a camera column
when there are several sensors);
OUTPUT_OBSERVATIONS: the markers' pinned locations on the imported cameras (type control for a
marker with reference coordinates, tie without; point_id = the marker's label);
OUTPUT_POINTS: the markers' reference coordinates in CRS as a ground point table (role
control when the reference is enabled in Metashape, check when not; the marker accuracy as
sigma). The camera XML has no tie points.</source>
            <translation>## Saídas
OUTPUT_CAMERA: as câmeras (metashape_&lt;id do sensor&gt;); OUTPUT_EO: uma linha por câmera importada
(image_id = o rótulo da câmera, ou seu nome de arquivo com IMAGE_NAMES file; com uma coluna camera
quando há vários sensores);
OUTPUT_OBSERVATIONS: as posições fixadas dos marcadores nas câmeras importadas (tipo control para
um marcador com coordenadas de referência, tie sem elas; point_id = o rótulo do marcador);
OUTPUT_POINTS: as coordenadas de referência dos marcadores em CRS como tabela de pontos de apoio
(papel control quando a referência está habilitada no Metashape, check quando não; a precisão do
marcador como desvio-padrão). O XML de câmeras não tem pontos de ligação.</translation>
        </message>
        <message>
            <source>Metashape camera file (XML)</source>
            <translation>Arquivo de câmeras do Metashape (XML)</translation>
        </message>
        <message>
            <source>Metashape cameras (*.xml);;All files (*)</source>
            <translation>Câmeras do Metashape (*.xml);;Todos os arquivos (*)</translation>
        </message>
        <message>
            <source>Mapping CRS</source>
            <translation>SRC de mapeamento</translation>
        </message>
        <message>
            <source>the projected CRS to convert to; empty: the chunk's own (projected) CRS</source>
            <translation>o SRC projetado de destino; vazio: o SRC (projetado) do próprio chunk</translation>
        </message>
        <message>
            <source>Pixel size</source>
            <translation>Tamanho do pixel</translation>
        </message>
        <message>
            <source>used when a sensor states no pixel_width: it sets the millimetres of the camera, never the projection</source>
            <translation>usado quando um sensor não declara pixel_width: define os milímetros da câmera, nunca a projeção</translation>
        </message>
        <message>
            <source>Image names in the EO</source>
            <translation>Nomes das imagens na OE</translation>
        </message>
        <message>
            <source>label: the camera labels as Metashape shows them; file: their file names without folder and extension (how orthorectify and the picking dock find images)</source>
            <translation>label: os rótulos das câmeras como o Metashape os mostra; file: seus nomes de arquivo sem pasta nem extensão (como orthorectify e o painel de medição encontram as imagens)</translation>
        </message>
        <message>
            <source>Cameras (JSON)</source>
            <translation>Câmeras (JSON)</translation>
        </message>
        <message>
            <source>JSON files (*.json)</source>
            <translation>Arquivos JSON (*.json)</translation>
        </message>
        <message>
            <source>Exterior orientation table (CSV)</source>
            <translation>Tabela de orientação exterior (CSV)</translation>
        </message>
        <message>
            <source>CSV files (*.csv)</source>
            <translation>Arquivos CSV (*.csv)</translation>
        </message>
        <message>
            <source>Observations (tie points, CSV)</source>
            <translation>Observações (pontos de ligação, CSV)</translation>
        </message>
        <message>
            <source>3D points (ground point table, CSV)</source>
            <translation>Pontos 3D (tabela de pontos de apoio, CSV)</translation>
        </message>
        <message>
            <source>Number of imported cameras</source>
            <translation>Número de câmeras importadas</translation>
        </message>
        <message>
            <source>Number of cameras</source>
            <translation>Número de câmeras</translation>
        </message>
        <message>
            <source>Number of 3D points</source>
            <translation>Número de pontos 3D</translation>
        </message>
        <message>
            <source>Number of skipped cameras</source>
            <translation>Número de câmeras ignoradas</translation>
        </message>
    </context>
    <context>
        <name>lidarphoto:importopensfm</name>
        <message>
            <source>Import OpenSfM / ODM reconstruction</source>
            <translation>Importar reconstrução OpenSfM / ODM</translation>
        </message>
        <message>
            <source>Aerotriangulation</source>
            <translation>Aerotriangulação</translation>
        </message>
        <message>
            <source>OpenSfM or ODM reconstruction.json -&gt; cameras, orientations, tie points</source>
            <translation>reconstruction.json do OpenSfM ou do ODM -&gt; câmeras, orientações, pontos de ligação</translation>
        </message>
        <message>
            <source>Reads an OpenSfM reconstruction (reconstruction.json, as OpenSfM and OpenDroneMap write it,
with tracks.csv beside it when present) and writes the project's camera JSON, exterior
orientation, observation table and points, with the lens models converted exactly: OpenSfM's
distortion maps ideal to measured coordinates, and each camera gets the forward lens model
with OpenSfM's own coefficients (docs/formats.md, OpenSfM). The perspective, simple_radial,
radial, brown, fisheye and fisheye_opencv projection types are supported; spherical, dual and
fisheye62/624 are refused by name.</source>
            <translation>Lê uma reconstrução OpenSfM (reconstruction.json, como o OpenSfM e o OpenDroneMap a escrevem,
com o tracks.csv ao lado quando existe) e escreve o JSON de câmera do projeto, a orientação
exterior, a tabela de observações e os pontos, com os modelos de lente convertidos exatamente: a
distorção do OpenSfM leva coordenadas ideais a medidas, e cada câmera recebe o modelo de lente direto
com os próprios coeficientes do OpenSfM (docs/formats.md, OpenSfM). Os tipos de projeção perspective, simple_radial,
radial, brown, fisheye e fisheye_opencv são aceitos; spherical, dual e
fisheye62/624 são recusados pelo nome.</translation>
        </message>
        <message>
            <source>## Frame
OpenSfM's coordinates are topocentric (east, north, up) at reference_lla. CRS empty: they
are kept as they are (LOCAL, no CRS); a projected CRS (e.g. EPSG:32723): they are converted
into it through ECEF, with each orientation turned to the grid frame at its centre.</source>
            <translation>## Referencial
As coordenadas do OpenSfM são topocêntricas (leste, norte, acima) em reference_lla. CRS vazio:
ficam como estão (LOCAL, sem CRS); um CRS projetado (p. ex. EPSG:32723): são convertidas
para ele via ECEF, com cada orientação girada para o referencial da quadrícula em seu centro.</translation>
        </message>
        <message>
            <source>## Inputs
INPUT: reconstruction.json (or its folder); RECONSTRUCTION: which of its reconstructions (0:
the first, the largest). PIXEL_SIZE: OpenSfM has none; it scales the millimetres, never the
projection.</source>
            <translation>## Entradas
INPUT: reconstruction.json (ou a sua pasta); RECONSTRUCTION: qual das suas reconstruções (0:
a primeira, a maior). PIXEL_SIZE: o OpenSfM não tem; ele escala os milímetros, nunca a
projeção.</translation>
        </message>
        <message>
            <source>## Outputs
OUTPUT_CAMERA: the cameras (opensfm_&lt;id&gt;); OUTPUT_EO: one row per shot (image_id = the shot's
image name, with a camera column when there are several); OUTPUT_OBSERVATIONS: the tracks of
tracks.csv as tie rows (point_id = the track id); OUTPUT_POINTS: the 3D points as a ground
point table with role check (triangulated tie points, never control).</source>
            <translation>## Saídas
OUTPUT_CAMERA: as câmeras (opensfm_&lt;id&gt;); OUTPUT_EO: uma linha por tomada (image_id = o nome da
imagem da tomada, com uma coluna de câmera quando há várias); OUTPUT_OBSERVATIONS: os rastros do
tracks.csv como linhas tie (point_id = o id do rastro); OUTPUT_POINTS: os pontos 3D como tabela de
pontos de apoio com papel check (pontos de ligação triangulados, nunca controle).</translation>
        </message>
        <message>
            <source>OpenSfM reconstruction (reconstruction.json)</source>
            <translation>Reconstrução OpenSfM (reconstruction.json)</translation>
        </message>
        <message>
            <source>OpenSfM reconstruction (*.json);;All files (*)</source>
            <translation>Reconstrução OpenSfM (*.json);;Todos os arquivos (*)</translation>
        </message>
        <message>
            <source>Mapping CRS</source>
            <translation>CRS de mapeamento</translation>
        </message>
        <message>
            <source>the projected CRS to convert to; empty: the topocentric frame (LOCAL)</source>
            <translation>o CRS projetado para o qual converter; vazio: o referencial topocêntrico (LOCAL)</translation>
        </message>
        <message>
            <source>Reconstruction index</source>
            <translation>Índice da reconstrução</translation>
        </message>
        <message>
            <source>which reconstruction of the file (0: the first)</source>
            <translation>qual reconstrução do arquivo (0: a primeira)</translation>
        </message>
        <message>
            <source>Pixel size</source>
            <translation>Tamanho do pixel</translation>
        </message>
        <message>
            <source>OpenSfM stores none: it sets the millimetres of the camera</source>
            <translation>o OpenSfM não guarda: define os milímetros da câmera</translation>
        </message>
        <message>
            <source>Cameras (JSON)</source>
            <translation>Câmeras (JSON)</translation>
        </message>
        <message>
            <source>JSON files (*.json)</source>
            <translation>Arquivos JSON (*.json)</translation>
        </message>
        <message>
            <source>Exterior orientation table (CSV)</source>
            <translation>Tabela de orientação exterior (CSV)</translation>
        </message>
        <message>
            <source>CSV files (*.csv)</source>
            <translation>Arquivos CSV (*.csv)</translation>
        </message>
        <message>
            <source>Observations (tie points, CSV)</source>
            <translation>Observações (pontos de ligação, CSV)</translation>
        </message>
        <message>
            <source>3D points (ground point table, CSV)</source>
            <translation>Pontos 3D (tabela de pontos de apoio, CSV)</translation>
        </message>
        <message>
            <source>Number of shots</source>
            <translation>Número de tomadas</translation>
        </message>
        <message>
            <source>Number of cameras</source>
            <translation>Número de câmeras</translation>
        </message>
        <message>
            <source>Number of 3D points</source>
            <translation>Número de pontos 3D</translation>
        </message>
    </context>
    <context>
        <name>lidarphoto:importpix4d</name>
        <message>
            <source>Import Pix4D calibrated cameras</source>
            <translation>Importar câmeras calibradas do Pix4D</translation>
        </message>
        <message>
            <source>Aerotriangulation</source>
            <translation>Aerotriangulação</translation>
        </message>
        <message>
            <source>Pix4D calibrated_camera_parameters.txt -&gt; cameras (exact lens model), orientations</source>
            <translation>calibrated_camera_parameters.txt do Pix4D -&gt; câmeras (modelo de lente exato), orientações</translation>
        </message>
        <message>
            <source>Reads the file PIX4Dmapper writes in 1_initial/params, &lt;project&gt;_calibrated_camera_parameters.txt
(per image: K, radial R1 R2 R3, tangential T1 T2, position t and rotation R, with
m = K [R | -R t] X on the coordinates minus &lt;project&gt;_offset.xyz), and writes the project's
camera JSON and exterior orientation with the lens converted exactly: the forward OpenCV
model with Pix4D's coefficients (k1..k3 = R1..R3, p1 = T1, p2 = T2; docs/formats.md, Pix4D).
Images with the same K and coefficients share a camera. A K with skew is refused by name.</source>
            <translation>Lê o arquivo que o PIX4Dmapper escreve em 1_initial/params, &lt;project&gt;_calibrated_camera_parameters.txt
(por imagem: K, radiais R1 R2 R3, tangenciais T1 T2, posição t e rotação R, com
m = K [R | -R t] X sobre as coordenadas menos &lt;project&gt;_offset.xyz), e escreve o JSON de câmera e
a orientação exterior do projeto com a lente convertida exatamente: o modelo OpenCV direto com os
coeficientes do Pix4D (k1..k3 = R1..R3, p1 = T1, p2 = T2; docs/formats.md, Pix4D).
Imagens com o mesmo K e coeficientes compartilham uma câmera. Um K com cisalhamento é recusado pelo nome.</translation>
        </message>
        <message>
            <source>## Assumptions
Pix4D's documentation found does not state the pixel origin of K nor show the distortion
formula in the y-down frame of this file: the tangential terms are read as OpenCV's in that
frame, and PIXEL_ORIGIN says whether K's pixels start at the image's corner (default) or at
the centre of the first pixel.</source>
            <translation>## Suposições
A documentação do Pix4D encontrada não declara a origem dos pixels de K nem mostra a fórmula de
distorção no referencial com y para baixo deste arquivo: os termos tangenciais são lidos como os
do OpenCV nesse referencial, e PIXEL_ORIGIN diz se os pixels de K começam no canto da imagem
(padrão) ou no centro do primeiro pixel.</translation>
        </message>
        <message>
            <source>## Frame
OFFSET: the &lt;project&gt;_offset.xyz (empty: the one beside INPUT; none found: no offset, said in
the log). CRS: the output CRS Pix4D used (empty: the &lt;project&gt;_wkt.prj beside INPUT when there
is one, else LOCAL); the coordinates are its easting, northing and height.</source>
            <translation>## Referencial
OFFSET: o &lt;project&gt;_offset.xyz (vazio: o que está ao lado de INPUT; nenhum encontrado: sem
offset, dito no log). CRS: o SRC de saída que o Pix4D usou (vazio: o &lt;project&gt;_wkt.prj ao lado
de INPUT quando existe, senão LOCAL); as coordenadas são seus E, N e altura.</translation>
        </message>
        <message>
            <source>## Outputs
OUTPUT_CAMERA: the cameras (pix4d_1, pix4d_2, ...); OUTPUT_EO: one row per image (image_id =
the image's file name as Pix4D writes it; with a camera column when there are several). The
file has no tie points.</source>
            <translation>## Saídas
OUTPUT_CAMERA: as câmeras (pix4d_1, pix4d_2, ...); OUTPUT_EO: uma linha por imagem (image_id =
o nome de arquivo da imagem como o Pix4D o escreve; com uma coluna camera quando há várias). O
arquivo não tem pontos de enlace.</translation>
        </message>
        <message>
            <source>Pix4D calibrated camera parameters (TXT)</source>
            <translation>Parâmetros calibrados de câmera do Pix4D (TXT)</translation>
        </message>
        <message>
            <source>Pix4D calibrated cameras (*_calibrated_camera_parameters.txt);;All files (*)</source>
            <translation>Câmeras calibradas do Pix4D (*_calibrated_camera_parameters.txt);;Todos os arquivos (*)</translation>
        </message>
        <message>
            <source>Pix4D offset (XYZ)</source>
            <translation>Offset do Pix4D (XYZ)</translation>
        </message>
        <message>
            <source>empty: &lt;project&gt;_offset.xyz beside INPUT</source>
            <translation>vazio: &lt;project&gt;_offset.xyz ao lado de INPUT</translation>
        </message>
        <message>
            <source>Pix4D offset (*_offset.xyz);;All files (*)</source>
            <translation>Offset do Pix4D (*_offset.xyz);;Todos os arquivos (*)</translation>
        </message>
        <message>
            <source>Output CRS of the Pix4D project</source>
            <translation>SRC de saída do projeto Pix4D</translation>
        </message>
        <message>
            <source>empty: &lt;project&gt;_wkt.prj beside INPUT, else LOCAL</source>
            <translation>vazio: &lt;project&gt;_wkt.prj ao lado de INPUT, senão LOCAL</translation>
        </message>
        <message>
            <source>Pixel size</source>
            <translation>Tamanho do pixel</translation>
        </message>
        <message>
            <source>the file states none: it sets the millimetres of the camera, never the projection</source>
            <translation>o arquivo não declara nenhum: define os milímetros da câmera, nunca a projeção</translation>
        </message>
        <message>
            <source>Pixel origin of K</source>
            <translation>Origem dos pixels de K</translation>
        </message>
        <message>
            <source>corner: K's pixel coordinates start at the image's top-left corner; centre: the first pixel's centre is (0, 0)</source>
            <translation>corner: as coordenadas de pixel de K começam no canto superior esquerdo da imagem; centre: o centro do primeiro pixel é (0, 0)</translation>
        </message>
        <message>
            <source>Cameras (JSON)</source>
            <translation>Câmeras (JSON)</translation>
        </message>
        <message>
            <source>JSON files (*.json)</source>
            <translation>Arquivos JSON (*.json)</translation>
        </message>
        <message>
            <source>Exterior orientation table (CSV)</source>
            <translation>Tabela de orientação exterior (CSV)</translation>
        </message>
        <message>
            <source>CSV files (*.csv)</source>
            <translation>Arquivos CSV (*.csv)</translation>
        </message>
        <message>
            <source>Observations (tie points, CSV)</source>
            <translation>Observações (pontos de ligação, CSV)</translation>
        </message>
        <message>
            <source>3D points (ground point table, CSV)</source>
            <translation>Pontos 3D (tabela de pontos de apoio, CSV)</translation>
        </message>
        <message>
            <source>Number of imported images</source>
            <translation>Número de imagens importadas</translation>
        </message>
        <message>
            <source>Number of cameras</source>
            <translation>Número de câmeras</translation>
        </message>
        <message>
            <source>Number of 3D points</source>
            <translation>Número de pontos 3D</translation>
        </message>
    </context>
    <context>
        <name>lidarphoto:importtrajectory</name>
        <message>
            <source>Import trajectory at camera events</source>
            <translation>Importar trajetória nos eventos da câmera</translation>
        </message>
        <message>
            <source>Aerotriangulation</source>
            <translation>Aerotriangulação</translation>
        </message>
        <message>
            <source>SBET / POSPac / Inertial Explorer / CSV trajectory + camera events -&gt; pose per image</source>
            <translation>trajetória SBET / POSPac / Inertial Explorer / CSV + eventos da câmera -&gt; pose por imagem</translation>
        </message>
        <message>
            <source>Reads the INS/GNSS solution as delivered (an Applanix SBET, a POSPac or Inertial Explorer
ASCII export, or a generic CSV at any rate) and the camera's event file (image_id, time),
and interpolates the pose of every image at its exposure:</source>
            <translation>Lê a solução INS/GNSS como é entregue (um SBET da Applanix, uma exportação ASCII do POSPac
ou do Inertial Explorer, ou um CSV genérico com qualquer frequência) e o arquivo de eventos da
câmera (image_id, time), e interpola a pose de cada imagem no instante da sua exposição:</translation>
        </message>
        <message>
            <source>- trajectory time = event time + TIME_OFFSET (the camera's timing offset, seconds);
- position: cubic Hermite in the Earth-centred frame, with the records' velocities when the
  file has them (they are checked against the positions);
- attitude: spherical interpolation of the body-to-Earth-centred rotation (quaternions; a
  cubic on the rotation group with the angular velocities of the neighbouring records, or
  SLERP with ATTITUDE slerp), so a heading through north and the SBET's wander angle (true
  heading = platform heading - wander) need no special case;
- an event outside the trajectory, or in an interval between records longer than MAX_GAP,
  is refused by name, and nothing is written.</source>
            <translation>- tempo da trajetória = tempo do evento + TIME_OFFSET (o atraso de tempo da câmera, segundos);
- posição: Hermite cúbica no referencial geocêntrico, com as velocidades dos registros quando
  o arquivo as tem (elas são verificadas contra as posições);
- atitude: interpolação esférica da rotação do corpo para o referencial geocêntrico
  (quatérnios; uma cúbica no grupo das rotações com as velocidades angulares dos registros
  vizinhos, ou SLERP com ATTITUDE slerp), de modo que um rumo passando pelo norte e o ângulo
  wander do SBET (rumo verdadeiro = rumo da plataforma - wander) não precisam de caso especial;
- um evento fora da trajetória, ou num intervalo entre registros maior que MAX_GAP, é recusado
  pelo nome, e nada é escrito.</translation>
        </message>
        <message>
            <source>## Inputs
INPUT: the trajectory; FORMAT auto picks SBET for .out/.sbet, the generic CSV for .csv and
an ASCII export otherwise (docs/formats.md). Latitude and longitude are on the datum of the
mapping CRS. EVENTS: CSV with image_id, time and optionally group; EVENT_TIME gps (seconds of
the GPS week, the SBET's clock) or utc (ISO 8601 date-times, with LEAP_SECONDS = GPS - UTC,
18 s since 2017).</source>
            <translation>## Entradas
INPUT: a trajetória; FORMAT auto escolhe SBET para .out/.sbet, o CSV genérico para .csv e uma
exportação ASCII nos outros casos (docs/formats.md). Latitude e longitude estão no datum do
SRC de mapeamento. EVENTS: CSV com image_id, time e opcionalmente group; EVENT_TIME gps
(segundos da semana GPS, o relógio do SBET) ou utc (data-hora ISO 8601, com LEAP_SECONDS =
GPS - UTC, 18 s desde 2017).</translation>
        </message>
        <message>
            <source>## Outputs
OUTPUT_TRAJECTORY: the trajectory table that trajectorytoeo and boresightcalibration read
(easting, northing, height in the mapping CRS; roll, pitch, true heading in degrees; the
velocity v_north, v_east, v_up in m/s, which boresightcalibration's timing offset uses; time =
the trajectory time). OUTPUT_EO: the exterior orientation with the mount applied, as
trajectorytoeo computes it. OUTPUT: the perspective centres as a PointZ layer.</source>
            <translation>## Saídas
OUTPUT_TRAJECTORY: a tabela de trajetória que trajectorytoeo e boresightcalibration leem
(E, N, altura no SRC de mapeamento; rolamento, arfagem e rumo verdadeiro em graus; a
velocidade v_north, v_east, v_up em m/s, que o atraso de disparo de boresightcalibration
usa; time = o tempo da trajetória). OUTPUT_EO: a orientação exterior com a montagem aplicada,
como trajectorytoeo a calcula. OUTPUT: os centros perspectivos como camada PointZ.</translation>
        </message>
        <message>
            <source>Trajectory (SBET, ASCII export or CSV)</source>
            <translation>Trajetória (SBET, exportação ASCII ou CSV)</translation>
        </message>
        <message>
            <source>Trajectories (*.out *.sbet *.txt *.asc *.csv *.OUT);;All files (*)</source>
            <translation>Trajetórias (*.out *.sbet *.txt *.asc *.csv *.OUT);;Todos os arquivos (*)</translation>
        </message>
        <message>
            <source>Trajectory format</source>
            <translation>Formato da trajetória</translation>
        </message>
        <message>
            <source>auto: by the file's ending (.out/.sbet SBET, .csv CSV, else ASCII)</source>
            <translation>auto: pela extensão do arquivo (.out/.sbet SBET, .csv CSV, senão ASCII)</translation>
        </message>
        <message>
            <source>Camera events (CSV: image_id, time)</source>
            <translation>Eventos da câmera (CSV: image_id, time)</translation>
        </message>
        <message>
            <source>CSV files (*.csv *.txt)</source>
            <translation>Arquivos CSV (*.csv *.txt)</translation>
        </message>
        <message>
            <source>Clock of the event times</source>
            <translation>Relógio dos tempos dos eventos</translation>
        </message>
        <message>
            <source>gps: GPS seconds of week; utc: ISO 8601 date-times in UTC</source>
            <translation>gps: segundos da semana GPS; utc: data-hora ISO 8601 em UTC</translation>
        </message>
        <message>
            <source>Leap seconds GPS - UTC</source>
            <translation>Segundos intercalares GPS - UTC</translation>
        </message>
        <message>
            <source>GPS - UTC at the events' date (18 since 2017-01-01); used for utc times</source>
            <translation>GPS - UTC na data dos eventos (18 desde 2017-01-01); usado para tempos utc</translation>
        </message>
        <message>
            <source>Camera timing offset</source>
            <translation>Atraso de tempo da câmera</translation>
        </message>
        <message>
            <source>trajectory time = event time + offset</source>
            <translation>tempo da trajetória = tempo do evento + atraso</translation>
        </message>
        <message>
            <source>Longest record interval</source>
            <translation>Maior intervalo entre registros</translation>
        </message>
        <message>
            <source>an event between two records further apart than this is refused</source>
            <translation>um evento entre dois registros mais afastados do que isto é recusado</translation>
        </message>
        <message>
            <source>Attitude interpolation</source>
            <translation>Interpolação da atitude</translation>
        </message>
        <message>
            <source>cubic: Hermite cubic on the rotation group with the neighbours' angular velocities; slerp: constant angular velocity between two records</source>
            <translation>cubic: Hermite cúbica no grupo das rotações com as velocidades angulares dos vizinhos; slerp: velocidade angular constante entre dois registros</translation>
        </message>
        <message>
            <source>Mapping CRS (projected)</source>
            <translation>SRC de mapeamento (projetado)</translation>
        </message>
        <message>
            <source>projected CRS of the outputs (and of a CSV's eastings/northings)</source>
            <translation>SRC projetado das saídas (e das coordenadas E/N de um CSV)</translation>
        </message>
        <message>
            <source>Lever arm x,y,z</source>
            <translation>Braço de alavanca x,y,z</translation>
        </message>
        <message>
            <source>camera perspective centre in the INS body frame (x forward, y right, z down)</source>
            <translation>centro perspectivo da câmera no referencial do corpo do INS (x para a frente, y para a direita, z para baixo)</translation>
        </message>
        <message>
            <source>Camera mount</source>
            <translation>Montagem da câmera</translation>
        </message>
        <message>
            <source>nominal camera-to-body rotation; custom uses MOUNT_MATRIX</source>
            <translation>rotação nominal da câmera para o corpo; custom usa MOUNT_MATRIX</translation>
        </message>
        <message>
            <source>image_top_forward: image top towards the flight direction (nose)</source>
            <translation>image_top_forward: topo da imagem no sentido do voo (nariz)</translation>
        </message>
        <message>
            <source>image_right_forward: image right side towards the flight direction</source>
            <translation>image_right_forward: lado direito da imagem no sentido do voo</translation>
        </message>
        <message>
            <source>image_bottom_forward: image bottom towards the flight direction</source>
            <translation>image_bottom_forward: base da imagem no sentido do voo</translation>
        </message>
        <message>
            <source>image_left_forward: image left side towards the flight direction</source>
            <translation>image_left_forward: lado esquerdo da imagem no sentido do voo</translation>
        </message>
        <message>
            <source>custom: custom matrix (MOUNT_MATRIX)</source>
            <translation>custom: matriz definida pelo usuário (MOUNT_MATRIX)</translation>
        </message>
        <message>
            <source>Mount matrix R_c^b (9 numbers, row-major)</source>
            <translation>Matriz de montagem R_c^b (9 números, por linhas)</translation>
        </message>
        <message>
            <source>the nominal mount R_c^b when MOUNT is custom</source>
            <translation>a montagem nominal R_c^b quando MOUNT é custom</translation>
        </message>
        <message>
            <source>Boresight domega,dphi,dkappa</source>
            <translation>Boresight domega,dphi,dkappa</translation>
        </message>
        <message>
            <source>small misalignment about the camera axes x, y, z (a larger rotation belongs in MOUNT)</source>
            <translation>pequeno desalinhamento em torno dos eixos x, y, z da câmera (uma rotação maior pertence a MOUNT)</translation>
        </message>
        <message>
            <source>Perspective centres</source>
            <translation>Centros perspectivos</translation>
        </message>
        <message>
            <source>Trajectory table at the events (CSV)</source>
            <translation>Tabela de trajetória nos eventos (CSV)</translation>
        </message>
        <message>
            <source>CSV files (*.csv)</source>
            <translation>Arquivos CSV (*.csv)</translation>
        </message>
        <message>
            <source>Exterior orientation table (CSV)</source>
            <translation>Tabela de orientação exterior (CSV)</translation>
        </message>
        <message>
            <source>Number of images</source>
            <translation>Número de imagens</translation>
        </message>
        <message>
            <source>Number of trajectory records</source>
            <translation>Número de registros da trajetória</translation>
        </message>
        <message>
            <source>## Outputs
OUTPUT_TRAJECTORY: the trajectory table that trajectorytoeo and boresightcalibration read
(easting, northing, height in the mapping CRS; roll, pitch, true heading in degrees; time =
the trajectory time). OUTPUT_EO: the exterior orientation with the mount applied, as
trajectorytoeo computes it. OUTPUT: the perspective centres as a PointZ layer.</source>
            <translation type="vanished">## Saídas
OUTPUT_TRAJECTORY: a tabela de trajetória que trajectorytoeo e boresightcalibration leem
(E, N, altura no SRC de mapeamento; rolamento, arfagem e rumo verdadeiro em graus; time = o
tempo da trajetória). OUTPUT_EO: a orientação exterior com a montagem aplicada, como
trajectorytoeo a calcula. OUTPUT: os centros perspectivos como camada PointZ.</translation>
        </message>
        <message>
            <source>Direct georeferencing</source>
            <translation type="vanished">Georreferenciação direta</translation>
        </message>
    </context>
    <context>
        <name>lidarphoto:lidaraccuracy</name>
        <message>
            <source>LiDAR swath and vertical accuracy (ASPRS 2023)</source>
            <translation>Acurácia LiDAR entre faixas e vertical (ASPRS 2023)</translation>
        </message>
        <message>
            <source>Accuracy</source>
            <translation>Acurácia</translation>
        </message>
        <message>
            <source>swath overlap difference, within-swath precision and NVA/VVA of a LiDAR survey</source>
            <translation>diferença na sobreposição de faixas, precisão dentro da faixa e NVA/VVA de um levantamento LiDAR</translation>
        </message>
        <message>
            <source>Tells how good a LiDAR survey itself is, under the ASPRS Positional Accuracy Standards,
Edition 2 (2023): relative accuracy between overlapping swaths, within-swath precision and
absolute vertical accuracy at surveyed check points.</source>
            <translation>Diz quão bom é o próprio levantamento LiDAR, segundo os ASPRS Positional Accuracy Standards,
Edição 2 (2023): acurácia relativa entre faixas sobrepostas, precisão dentro da faixa e
acurácia vertical absoluta em pontos de verificação levantados.</translation>
        </message>
        <message>
            <source>## Swaths
From the LAS point source id (flight line) when the cloud holds more than one, else from gaps
in GPS time longer than GPS gap (the report says which).</source>
            <translation>## Faixas
Do point source id do LAS (linha de voo) quando a nuvem tem mais de um, senão das lacunas
no tempo GPS maiores que a lacuna GPS (o relatório diz qual).</translation>
        </message>
        <message>
            <source>## Smooth hard cells
On a north-up grid of Cell size (corners on multiples of it), a cell of a swath is smooth
when it holds at least the least returns of that swath, no vegetation class (3-5), only single
returns (and, with Hard classes, only those classes), the least-squares plane through them has
a slope at most Max slope and a residual rms at most Max residual, and the planes of its
neighbour cells continue it within Max step (edges, walls and rough ground fail).</source>
            <translation>## Células lisas e rígidas
Numa grade orientada ao norte com o tamanho de célula (cantos em múltiplos dele), a célula de uma
faixa é lisa quando tem pelo menos o mínimo de retornos dessa faixa, nenhuma classe de vegetação
(3-5), só retornos únicos (e, com Classes rígidas, só essas classes), o plano de mínimos
quadrados por eles tem declividade no máximo a declividade máxima e rms dos resíduos no máximo o
resíduo máximo, e os planos das células vizinhas o continuam dentro do degrau máximo (bordas,
paredes e terreno rugoso falham).</translation>
        </message>
        <message>
            <source>## Figures
Swath overlap difference dz = h_a - h_b (plane heights at the cell centre) per swath pair and
overall: count, mean, RMSDz, max |dz|, surface-normal RMSD, the share beyond 0.8 and 1.6 times
the class, and the tilt of dz across the overlap (a roll error shows as a cross-track slope).
Within-swath precision per swath: pooled plane residual rms and the cells' Max Diff (range).
Check points (CSV id, e, n, h, group = land cover): dz = LiDAR - check, the LiDAR height
interpolated in a TIN of the ground returns (class 2); NVA (non-vegetated): RMSE_V with the
survey sigma, 1.96 RMSE_V for comparison; VVA (groups such as vegetated, forest, brush, crops):
RMSE and the 95th percentile of |dz|, reported only. Verdicts against a vertical class #-cm:
within-swath Max Diff &lt;= 0.6 #, swath RMSDz &lt;= 0.8 #, swath max &lt;= 1.6 #, NVA RMSE_V &lt;= #
with at least 30 check points (docs/formats.md "LiDAR accuracy").</source>
            <translation>## Figuras
Diferença na sobreposição dz = h_a - h_b (alturas dos planos no centro da célula) por par de
faixas e no total: contagem, média, RMSDz, máximo de |dz|, RMSD na normal da superfície, a
parcela além de 0,8 e 1,6 vezes a classe, e a inclinação de dz na sobreposição (um erro de
rolamento aparece como declividade transversal). Precisão dentro da faixa por faixa: rms
conjunto dos resíduos dos planos e a Max Diff (amplitude) das células. Pontos de verificação (CSV
id, e, n, h, group = cobertura do solo): dz = LiDAR - ponto, a altura LiDAR interpolada numa TIN
dos retornos de solo (classe 2); NVA (não vegetado): RMSE_V com o sigma do levantamento, 1,96
RMSE_V para comparação; VVA (grupos como vegetated, forest, brush, crops): RMSE e o percentil
95 de |dz|, só informados. Veredictos para uma classe vertical #-cm: Max Diff dentro da faixa
&lt;= 0,6 #, RMSDz entre faixas &lt;= 0,8 #, máximo entre faixas &lt;= 1,6 #, NVA RMSE_V &lt;= # com pelo
menos 30 pontos de verificação (docs/formats.md "LiDAR accuracy").</translation>
        </message>
        <message>
            <source>## Outputs
HTML report, JSON of every figure, a GeoTIFF of dz with one band per swath pair, and the check
points with the LiDAR heights as a check-point table (id, e, n, h, e_ref, n_ref, h_ref, group)
that accuracyreport reads for the NSSDA and PEC-PCD sections.</source>
            <translation>## Saídas
Relatório HTML, JSON com todas as figuras, um GeoTIFF de dz com uma banda por par de faixas, e
os pontos de verificação com as alturas LiDAR como tabela de pontos de verificação (id, e, n, h,
e_ref, n_ref, h_ref, group) que o accuracyreport lê para as seções NSSDA e PEC-PCD.</translation>
        </message>
        <message>
            <source>Point clouds (LAS/LAZ files or folders)</source>
            <translation>Nuvens de pontos (arquivos LAS/LAZ ou pastas)</translation>
        </message>
        <message>
            <source>LAS/LAZ files of one survey, or folders of them</source>
            <translation>arquivos LAS/LAZ de um levantamento, ou pastas deles</translation>
        </message>
        <message>
            <source>Check points (CSV: id, e, n, h, group)</source>
            <translation>Pontos de verificação (CSV: id, e, n, h, group)</translation>
        </message>
        <message>
            <source>surveyed check points; group = land cover</source>
            <translation>pontos de verificação levantados; group = cobertura do solo</translation>
        </message>
        <message>
            <source>CSV files (*.csv *.txt)</source>
            <translation>Arquivos CSV (*.csv *.txt)</translation>
        </message>
        <message>
            <source>Swaths from</source>
            <translation>Faixas a partir de</translation>
        </message>
        <message>
            <source>point source id, else GPS time</source>
            <translation>point source id, senão tempo GPS</translation>
        </message>
        <message>
            <source>point source id</source>
            <translation>point source id</translation>
        </message>
        <message>
            <source>GPS time gaps</source>
            <translation>lacunas no tempo GPS</translation>
        </message>
        <message>
            <source>Hard classes only (e.g. 2,6; empty: any but vegetation)</source>
            <translation>Só classes rígidas (p. ex. 2,6; vazio: todas menos vegetação)</translation>
        </message>
        <message>
            <source>LAS classes of hard surfaces; a cell holding another class is not compared (class 1 holds cars that move between flights)</source>
            <translation>classes LAS de superfícies rígidas; uma célula com outra classe não é comparada (a classe 1 tem carros que se movem entre voos)</translation>
        </message>
        <message>
            <source>Cell size (about 2 x point spacing or more)</source>
            <translation>Tamanho da célula (cerca de 2 x o espaçamento dos pontos ou mais)</translation>
        </message>
        <message>
            <source>Least returns of one swath in a cell</source>
            <translation>Mínimo de retornos de uma faixa numa célula</translation>
        </message>
        <message>
            <source>Largest slope of a smooth cell</source>
            <translation>Maior declividade de uma célula lisa</translation>
        </message>
        <message>
            <source>Largest plane-fit rms of a smooth cell</source>
            <translation>Maior rms do ajuste do plano de uma célula lisa</translation>
        </message>
        <message>
            <source>Largest step to a neighbour cell's plane</source>
            <translation>Maior degrau até o plano de uma célula vizinha</translation>
        </message>
        <message>
            <source>GPS-time gap that starts a new swath</source>
            <translation>Lacuna no tempo GPS que inicia uma nova faixa</translation>
        </message>
        <message>
            <source>Least smooth cells of an assessed swath pair</source>
            <translation>Mínimo de células lisas de um par de faixas avaliado</translation>
        </message>
        <message>
            <source>ASPRS vertical class (0 = report the class met)</source>
            <translation>Classe vertical ASPRS (0 = informar a classe atendida)</translation>
        </message>
        <message>
            <source>Check-point survey sigma in height</source>
            <translation>Sigma do levantamento dos pontos de verificação em altura</translation>
        </message>
        <message>
            <source>Ground returns within this distance make the TIN</source>
            <translation>Retornos de solo dentro desta distância formam a TIN</translation>
        </message>
        <message>
            <source>Tile size (0 = one process)</source>
            <translation>Tamanho do tile (0 = um processo)</translation>
        </message>
        <message>
            <source>tiles of this side (rounded up to whole cells) on a dask cluster, as lidarblock; needs point source ids</source>
            <translation>tiles deste lado (arredondado para células inteiras) num cluster dask, como o lidarblock; requer os point source ids</translation>
        </message>
        <message>
            <source>dask scheduler address (empty: a local cluster)</source>
            <translation>endereço do scheduler dask (vazio: um cluster local)</translation>
        </message>
        <message>
            <source>e.g. tcp://10.0.0.5:8786</source>
            <translation>por exemplo, tcp://10.0.0.5:8786</translation>
        </message>
        <message>
            <source>Local cluster: workers (0 = one per core)</source>
            <translation>Cluster local: trabalhadores (workers) (0 = um por núcleo)</translation>
        </message>
        <message>
            <source>Local cluster: memory limit per worker (0 = RAM / workers)</source>
            <translation>Cluster local: limite de memória por trabalhador (worker) (0 = RAM / trabalhadores)</translation>
        </message>
        <message>
            <source>Local cluster workers</source>
            <translation>Trabalhadores (workers) do cluster local</translation>
        </message>
        <message>
            <source>auto: processes on the command line, threads inside QGIS or qgis_process, where a process cluster would start QGIS's own executable for each worker</source>
            <translation>auto: processos na linha de comando, threads dentro do QGIS ou do qgis_process, onde um cluster de processos iniciaria o próprio executável do QGIS para cada trabalhador (worker)</translation>
        </message>
        <message>
            <source>auto (processes on the command line, threads inside QGIS)</source>
            <translation>auto (processos na linha de comando, threads dentro do QGIS)</translation>
        </message>
        <message>
            <source>processes (one per worker)</source>
            <translation>processos (um por trabalhador)</translation>
        </message>
        <message>
            <source>threads of this process</source>
            <translation>threads deste processo</translation>
        </message>
        <message>
            <source>LiDAR accuracy report (HTML)</source>
            <translation>Relatório de acurácia LiDAR (HTML)</translation>
        </message>
        <message>
            <source>HTML files (*.html)</source>
            <translation>Arquivos HTML (*.html)</translation>
        </message>
        <message>
            <source>LiDAR accuracy figures (JSON)</source>
            <translation>Figuras de acurácia LiDAR (JSON)</translation>
        </message>
        <message>
            <source>JSON files (*.json)</source>
            <translation>Arquivos JSON (*.json)</translation>
        </message>
        <message>
            <source>Swath overlap dz (GeoTIFF, a band per pair)</source>
            <translation>dz na sobreposição de faixas (GeoTIFF, uma banda por par)</translation>
        </message>
        <message>
            <source>Check points with LiDAR heights (CSV)</source>
            <translation>Pontos de verificação com alturas LiDAR (CSV)</translation>
        </message>
        <message>
            <source>Swath-to-swath RMSDz, all pairs (m)</source>
            <translation>RMSDz entre faixas, todos os pares (m)</translation>
        </message>
        <message>
            <source>Smooth cells compared</source>
            <translation>Células lisas comparadas</translation>
        </message>
        <message>
            <source>NVA RMSE_V (m; NaN without check points)</source>
            <translation>NVA RMSE_V (m; NaN sem pontos de verificação)</translation>
        </message>
        <message>
            <source>Quality</source>
            <translation type="vanished">Qualidade</translation>
        </message>
    </context>
    <context>
        <name>lidarphoto:lidarblock</name>
        <message>
            <source>LiDAR block: ground, roof planes and control, tile by tile (dask)</source>
            <translation>Bloco LiDAR: terreno, planos de telhado e controle, tile por tile (dask)</translation>
        </message>
        <message>
            <source>Blocks</source>
            <translation>Blocos</translation>
        </message>
        <message>
            <source>a whole LiDAR block tile by tile on dask.distributed: ground filter, roof planes, LiDAR control points and lines</source>
            <translation>um bloco LiDAR inteiro, tile por tile, no dask.distributed: filtro de terreno, planos de telhado, pontos e linhas de controle LiDAR</translation>
        </message>
        <message>
            <source>Runs the ground filter (SMRF, Pingel et al. 2013), the roof planes and the LiDAR control of
a whole block, one dask task per tile, on a local dask.distributed cluster (one worker per
core by default) or on an existing cluster (CLUSTER: its scheduler address, e.g.
tcp://10.0.0.5:8786; every worker must have lidarphoto and read the input paths).</source>
            <translation>Executa o filtro de terreno (SMRF, Pingel et al. 2013), os planos de telhado e o controle LiDAR de
um bloco inteiro, uma tarefa dask por tile, em um cluster dask.distributed local (um trabalhador (worker) por
núcleo por padrão) ou em um cluster existente (CLUSTER: o endereço do seu scheduler, por exemplo,
tcp://10.0.0.5:8786; todo trabalhador deve ter o lidarphoto e conseguir ler os caminhos de entrada).</translation>
        </message>
        <message>
            <source>Input: a folder of LAS/LAZ tiles, a virtual point cloud (.vpc, as made by PDAL or QGIS), or
one large LAS/LAZ file cut into square tiles of TILE_SIZE read in chunks. A COPC file (Cloud
Optimized Point Cloud) is read by octree node instead: each tile decompresses only the nodes
around its cell and buffer, where a plain LAZ is streamed whole by every tile. Tiles in
different CRSs are refused. Neighbours are found from the headers' bounding boxes.</source>
            <translation>Entrada: uma pasta de tiles LAS/LAZ, uma nuvem de pontos virtual (.vpc, como as criadas pelo PDAL ou QGIS), ou
um único arquivo LAS/LAZ grande, cortado em tiles quadrados de TILE_SIZE lidos em partes. Um arquivo COPC (Cloud
Optimized Point Cloud) é lido por nó da octree: cada tile descomprime só os nós
em torno da sua célula e do seu buffer, enquanto um LAZ comum é lido inteiro por cada tile. Tiles em
SRCs diferentes são recusados. Os vizinhos são encontrados pelas caixas envolventes dos cabeçalhos.</translation>
        </message>
        <message>
            <source>Buffers: each tile is filtered with the points of its neighbours within 2 x SMRF_WINDOW +
LOW_OUTLIER_RADIUS + 3 cells of its box, so its classes are those of a run on the whole cloud
(except a few points next to buildings within millimetres of the height tolerance: the DTM
filled under objects depends on the tile's grid corner; 9 of 75 256 points in the tests); only
the tile's own points are written. Roof planes are extracted on the tile plus three times
the reach of a point's label (its K_NEIGHBOURS patch and four rings of region-growing
neighbours); planes cut by a tile border are merged when both tiles' region growing put the
same points of the band along the border into them (never two planes one tile kept apart)
and refitted with their covariance, so the block has the planes of a single run; control
points and lines found by several tiles are kept once.</source>
            <translation>Buffers: cada tile é filtrado com os pontos dos seus vizinhos a até 2 x SMRF_WINDOW +
LOW_OUTLIER_RADIUS + 3 células da sua caixa, de modo que as suas classes são as de uma execução sobre a nuvem inteira
(exceto alguns pontos junto a edificações a milímetros da tolerância de altura: o MDT
preenchido sob os objetos depende do canto da grade do tile; 9 de 75 256 pontos nos testes); apenas
os pontos do próprio tile são gravados. Os planos de telhado são extraídos no tile mais três vezes o
alcance do rótulo de um ponto (a sua vizinhança K_NEIGHBOURS e quatro anéis de vizinhos do crescimento
de regiões); planos cortados por uma borda de tile são unidos quando o crescimento de regiões dos dois
tiles põe neles os mesmos pontos da faixa ao longo da borda (nunca dois planos que um tile manteve
separados) e reajustados com a sua covariância, de modo que o bloco tem os planos de uma execução única;
pontos e linhas de controle encontrados por vários tiles são mantidos uma única vez.</translation>
        </message>
        <message>
            <source>A tile that cannot be read is reported by name and skipped; the rest finishes and the block
is marked incomplete (report "complete": false, result COMPLETE 0, command-line exit
status 3).</source>
            <translation>Um tile que não pode ser lido é informado pelo nome e ignorado; o restante termina e o bloco
é marcado como incompleto (relatório "complete": false, resultado COMPLETE 0, status de saída da
linha de comando 3).</translation>
        </message>
        <message>
            <source>## Outputs
OUTPUT_FOLDER (must be new, empty, or a previous block output) receives, all at once when
the block is done: tiles/&lt;tile&gt;.laz (each tile's own points, class 2 ground, 7 low outliers,
other classes kept), block.vpc (the tiles as a virtual point cloud), planes.csv, lcps.csv,
lines.csv (the formats of Extract roof planes and Create LCPs) and block_report.json (per
tile: points, ground, seconds, peak memory, errors). Lengths are in the CRS unit unless
DISTANCE_UNIT is metres.</source>
            <translation>## Saídas
OUTPUT_FOLDER (deve ser nova, vazia, ou uma saída de bloco anterior) recebe, tudo de uma vez quando
o bloco termina: tiles/&lt;tile&gt;.laz (os pontos do próprio tile, classe 2 terreno, 7 outliers baixos,
demais classes mantidas), block.vpc (os tiles como nuvem de pontos virtual), planes.csv, lcps.csv,
lines.csv (os formatos de Extrair planos de telhado e Criar LCPs) e block_report.json (por
tile: pontos, terreno, segundos, pico de memória, erros). Os comprimentos estão na unidade do SRC, a menos que
DISTANCE_UNIT seja metros.</translation>
        </message>
        <message>
            <source>Block: folder of LAS/LAZ tiles, .vpc or one LAS/LAZ file</source>
            <translation>Bloco: pasta de tiles LAS/LAZ, .vpc ou um arquivo LAS/LAZ</translation>
        </message>
        <message>
            <source>a folder path is accepted too (its *.las/*.laz); COPC files are read by octree node</source>
            <translation>um caminho de pasta também é aceito (os seus *.las/*.laz); arquivos COPC são lidos por nó da octree</translation>
        </message>
        <message>
            <source>LAS/LAZ or virtual point cloud (*.las *.laz *.vpc)</source>
            <translation>LAS/LAZ ou nuvem de pontos virtual (*.las *.laz *.vpc)</translation>
        </message>
        <message>
            <source>CRS (overrides the file's)</source>
            <translation>SRC (substitui o do arquivo)</translation>
        </message>
        <message>
            <source>the cloud's CRS when the file has none or a wrong one (EPSG:xxxx or WKT)</source>
            <translation>o SRC da nuvem quando o arquivo não tem nenhum ou tem um errado (EPSG:xxxx ou WKT)</translation>
        </message>
        <message>
            <source>Distance unit</source>
            <translation>Unidade de distância</translation>
        </message>
        <message>
            <source>unit of the length parameters: the cloud's CRS unit (e.g. international feet) or metres, converted</source>
            <translation>unidade dos parâmetros de comprimento: a unidade do SRC da nuvem (por exemplo, pés internacionais) ou metros, convertidos</translation>
        </message>
        <message>
            <source>cloud CRS units</source>
            <translation>unidades do SRC da nuvem</translation>
        </message>
        <message>
            <source>metres</source>
            <translation>metros</translation>
        </message>
        <message>
            <source>Tile size (one large file)</source>
            <translation>Tamanho do tile (um arquivo grande)</translation>
        </message>
        <message>
            <source>side of the square tiles one file is cut into</source>
            <translation>lado dos tiles quadrados em que um arquivo é cortado</translation>
        </message>
        <message>
            <source>SMRF cell size</source>
            <translation>Tamanho da célula do SMRF</translation>
        </message>
        <message>
            <source>SMRF terrain slope</source>
            <translation>Declividade do terreno do SMRF</translation>
        </message>
        <message>
            <source>SMRF largest window radius</source>
            <translation>Maior raio de janela do SMRF</translation>
        </message>
        <message>
            <source>SMRF final height tolerance</source>
            <translation>Tolerância final de altura do SMRF</translation>
        </message>
        <message>
            <source>SMRF tolerance added per unit of slope</source>
            <translation>Tolerância do SMRF acrescida por unidade de declividade</translation>
        </message>
        <message>
            <source>Low outlier radius</source>
            <translation>Raio dos outliers baixos</translation>
        </message>
        <message>
            <source>Roof planes: point-to-plane tolerance</source>
            <translation>Planos de telhado: tolerância ponto-plano</translation>
        </message>
        <message>
            <source>Roof planes: neighbours of the local RANSAC</source>
            <translation>Planos de telhado: vizinhos do RANSAC local</translation>
        </message>
        <message>
            <source>Roof planes: smallest plane (points)</source>
            <translation>Planos de telhado: menor plano (pontos)</translation>
        </message>
        <message>
            <source>Control: adjacency distance delta</source>
            <translation>Controle: distância de adjacência delta</translation>
        </message>
        <message>
            <source>Control: minimum common boundary</source>
            <translation>Controle: fronteira comum mínima</translation>
        </message>
        <message>
            <source>dask scheduler address (empty: a local cluster)</source>
            <translation>endereço do scheduler dask (vazio: um cluster local)</translation>
        </message>
        <message>
            <source>e.g. tcp://10.0.0.5:8786</source>
            <translation>por exemplo, tcp://10.0.0.5:8786</translation>
        </message>
        <message>
            <source>Local cluster: workers (0 = one per core)</source>
            <translation>Cluster local: trabalhadores (workers) (0 = um por núcleo)</translation>
        </message>
        <message>
            <source>Local cluster: memory limit per worker (0 = RAM / workers)</source>
            <translation>Cluster local: limite de memória por trabalhador (worker) (0 = RAM / trabalhadores)</translation>
        </message>
        <message>
            <source>Local cluster workers</source>
            <translation>Trabalhadores (workers) do cluster local</translation>
        </message>
        <message>
            <source>auto: processes on the command line, threads inside QGIS or qgis_process, where a process cluster would start QGIS's own executable for each worker</source>
            <translation>auto: processos na linha de comando, threads dentro do QGIS ou do qgis_process, onde um cluster de processos iniciaria o próprio executável do QGIS para cada trabalhador (worker)</translation>
        </message>
        <message>
            <source>auto (processes on the command line, threads inside QGIS)</source>
            <translation>auto (processos na linha de comando, threads dentro do QGIS)</translation>
        </message>
        <message>
            <source>processes (one per worker)</source>
            <translation>processos (um por trabalhador)</translation>
        </message>
        <message>
            <source>threads of this process</source>
            <translation>threads deste processo</translation>
        </message>
        <message>
            <source>Output folder (tiles, VPC, tables, report)</source>
            <translation>Pasta de saída (tiles, VPC, tabelas, relatório)</translation>
        </message>
        <message>
            <source>Tiles processed</source>
            <translation>Tiles processados</translation>
        </message>
        <message>
            <source>Tiles that failed</source>
            <translation>Tiles que falharam</translation>
        </message>
        <message>
            <source>1 when every tile was processed, else 0</source>
            <translation>1 quando todos os tiles foram processados, senão 0</translation>
        </message>
        <message>
            <source>Points written</source>
            <translation>Pontos gravados</translation>
        </message>
        <message>
            <source>Ground points</source>
            <translation>Pontos de terreno</translation>
        </message>
        <message>
            <source>Roof planes</source>
            <translation>Planos de telhado</translation>
        </message>
        <message>
            <source>LiDAR control points</source>
            <translation>Pontos de controle LiDAR</translation>
        </message>
        <message>
            <source>LiDAR control lines</source>
            <translation>Linhas de controle LiDAR</translation>
        </message>
        <message>
            <source>LiDAR</source>
            <translation type="vanished">LiDAR</translation>
        </message>
        <message>
            <source>Input: a folder of LAS/LAZ tiles, a virtual point cloud (.vpc, as made by PDAL or QGIS), or
one large LAS/LAZ file cut into square tiles of TILE_SIZE read in chunks. Tiles in different
CRSs are refused. Neighbours are found from the headers' bounding boxes.</source>
            <translation type="vanished">Entrada: uma pasta de tiles LAS/LAZ, uma nuvem de pontos virtual (.vpc, como as criadas pelo PDAL ou QGIS), ou
um único arquivo LAS/LAZ grande, cortado em tiles quadrados de TILE_SIZE lidos em partes. Tiles em SRCs
diferentes são recusados. Os vizinhos são encontrados pelas caixas envolventes dos cabeçalhos.</translation>
        </message>
        <message>
            <source>a folder path is accepted too (its *.las/*.laz)</source>
            <translation type="vanished">um caminho de pasta também é aceito (os seus *.las/*.laz)</translation>
        </message>
    </context>
    <context>
        <name>lidarphoto:locatecontrolpoints</name>
        <message>
            <source>Locate control points in images (chips, NCC + least-squares matching)</source>
            <translation>Localizar pontos de controle em imagens (recortes/chips, NCC + correspondência por mínimos quadrados)</translation>
        </message>
        <message>
            <source>Aerotriangulation</source>
            <translation>Aerotriangulação</translation>
        </message>
        <message>
            <source>control points measured automatically in oriented images from control chips</source>
            <translation>pontos de controle medidos automaticamente em imagens orientadas a partir de recortes (chips) de controle</translation>
        </message>
        <message>
            <source>Each control point is projected into each image with its exterior orientation; its control
chip (a north-up GeoTIFF of the ground around the point, rectified onto the plane Z = Z_point,
file name = point id) is searched there by normalised cross-correlation with an adaptive
template size (grown until the predicted least-squares precision from the texture, Förstner
1986, passes), then refined by least-squares matching (Gruen 1985: 6 affine + 2 radiometric
parameters) from the chip's pixels with the local chip-to-image affine as start. Search
window: the EO sigmas (columns sigma_X .. sigma_kappa_deg of the EO CSV) propagated to the
image, times 3; without them +-SEARCH_PX pixels. A match is rejected, with the reason, for a
chip without texture, low correlation, no convergence, a sigma above MAX_SIGMA, a match
outside the search ellipse or a template partly outside the image. With TRANSFER, images where
the chip match failed are matched from the point's best image (image-to-image LSM). The camera
may be perspective or fisheye (equidistant, equisolid-angle, orthographic, stereographic,
Brown added): the prediction and the chip-to-image affine come from its own projection.</source>
            <translation>Cada ponto de controle é projetado em cada imagem com a sua orientação exterior; o seu recorte (chip)
de controle (um GeoTIFF com o norte para cima do terreno em torno do ponto, retificado sobre o plano Z = Z_point,
nome do arquivo = id do ponto) é buscado ali por correlação cruzada normalizada com um tamanho de
modelo (template) adaptativo (aumentado até que a precisão prevista por mínimos quadrados a partir da textura, Förstner
1986, seja aceita), e então refinado por correspondência por mínimos quadrados (Gruen 1985: 6 parâmetros afins + 2 radiométricos)
a partir dos pixels do recorte, com a afinidade local recorte-imagem como valor inicial. Janela
de busca: os sigmas da EO (colunas sigma_X .. sigma_kappa_deg do CSV da EO) propagados para a
imagem, vezes 3; sem eles, +-SEARCH_PX pixels. Uma correspondência é rejeitada, com o motivo, para um
recorte sem textura, correlação baixa, ausência de convergência, um sigma acima de MAX_SIGMA, uma correspondência
fora da elipse de busca ou um modelo parcialmente fora da imagem. Com TRANSFER, as imagens em que
a correspondência do recorte falhou são correspondidas a partir da melhor imagem do ponto (LSM imagem a imagem). A câmera pode
ser perspectiva ou olho de peixe (equidistante, de ângulo equissólido, ortográfica, estereográfica,
com Brown acrescentado): a predição e a afinidade recorte-imagem vêm da sua própria projeção.</translation>
        </message>
        <message>
            <source>Output: the image-observation CSV (image_id, point_id, col, row, sigma_px, type control,
empty target_id; point_id = the control point's id, also for the rows transferred from another
image), which bundleadjustment (with the control points as GROUND_POINTS), resection (with
them as CONTROL_POINTS) and boresightcalibration (with them as GROUND_POINTS) read directly;
sigma_px is the LSM sigma, at least SIGMA_FLOOR (LSM does not see the chip's own errors).
The report CSV has one row per point and image with the status and reason; the HTML report
shows the chips.</source>
            <translation>Saída: o CSV de observações de imagem (image_id, point_id, col, row, sigma_px, type control,
target_id vazio; point_id = o id do ponto de controle, também nas linhas transferidas de outra
imagem), que bundleadjustment (com os pontos de controle como GROUND_POINTS), resection (com
eles como CONTROL_POINTS) e boresightcalibration (com eles como GROUND_POINTS) leem
diretamente; sigma_px é o sigma da LSM, no mínimo SIGMA_FLOOR (a LSM não vê os erros do
próprio recorte). O CSV do relatório tem uma linha por ponto e imagem com o status e o motivo;
o relatório HTML mostra os recortes.</translation>
        </message>
        <message>
            <source>Control chips (GeoTIFF files or folders)</source>
            <translation>Recortes (chips) de controle (arquivos GeoTIFF ou pastas)</translation>
        </message>
        <message>
            <source>one GeoTIFF per point, named &lt;point_id&gt;.tif</source>
            <translation>um GeoTIFF por ponto, nomeado &lt;point_id&gt;.tif</translation>
        </message>
        <message>
            <source>Control points (CSV)</source>
            <translation>Pontos de controle (CSV)</translation>
        </message>
        <message>
            <source>point_id,X,Y,Z in the mapping CRS (the chips' CRS)</source>
            <translation>point_id,X,Y,Z no SRC de mapeamento (o SRC dos recortes)</translation>
        </message>
        <message>
            <source>CSV files (*.csv *.txt)</source>
            <translation>Arquivos CSV (*.csv *.txt)</translation>
        </message>
        <message>
            <source>Camera (JSON)</source>
            <translation>Câmera (JSON)</translation>
        </message>
        <message>
            <source>JSON files (*.json)</source>
            <translation>Arquivos JSON (*.json)</translation>
        </message>
        <message>
            <source>Exterior orientation (CSV)</source>
            <translation>Orientação exterior (CSV)</translation>
        </message>
        <message>
            <source>with sigma columns: the search window follows from them</source>
            <translation>com colunas de sigma: a janela de busca decorre delas</translation>
        </message>
        <message>
            <source>Images (files or folders)</source>
            <translation>Imagens (arquivos ou pastas)</translation>
        </message>
        <message>
            <source>image files (name = image_id), or folders whose images are all taken</source>
            <translation>arquivos de imagem (nome = image_id), ou pastas cujas imagens são todas tomadas</translation>
        </message>
        <message>
            <source>Mapping CRS of the EO and control</source>
            <translation>SRC de mapeamento da EO e do controle</translation>
        </message>
        <message>
            <source>e.g. EPSG:25832</source>
            <translation>por exemplo, EPSG:25832</translation>
        </message>
        <message>
            <source>Search half-width without EO sigmas</source>
            <translation>Semilargura da busca sem sigmas da EO</translation>
        </message>
        <message>
            <source>Smallest NCC peak</source>
            <translation>Menor pico de NCC</translation>
        </message>
        <message>
            <source>Smallest LSM correlation</source>
            <translation>Menor correlação da LSM</translation>
        </message>
        <message>
            <source>Largest LSM sigma</source>
            <translation>Maior sigma da LSM</translation>
        </message>
        <message>
            <source>Smallest sigma written</source>
            <translation>Menor sigma gravado</translation>
        </message>
        <message>
            <source>Transfer to images where the chip failed</source>
            <translation>Transferir para as imagens em que o recorte falhou</translation>
        </message>
        <message>
            <source>Image observations (CSV)</source>
            <translation>Observações de imagem (CSV)</translation>
        </message>
        <message>
            <source>CSV files (*.csv)</source>
            <translation>Arquivos CSV (*.csv)</translation>
        </message>
        <message>
            <source>Report per point and image (CSV)</source>
            <translation>Relatório por ponto e imagem (CSV)</translation>
        </message>
        <message>
            <source>Report with chip gallery (HTML)</source>
            <translation>Relatório com galeria de recortes (HTML)</translation>
        </message>
        <message>
            <source>HTML files (*.html)</source>
            <translation>Arquivos HTML (*.html)</translation>
        </message>
        <message>
            <source>Observations written</source>
            <translation>Observações gravadas</translation>
        </message>
        <message>
            <source>Point-image pairs rejected</source>
            <translation>Pares ponto-imagem rejeitados</translation>
        </message>
        <message>
            <source>Each control point is projected into each image with its exterior orientation; its control
chip (a north-up GeoTIFF of the ground around the point, rectified onto the plane Z = Z_point,
file name = point id) is searched there by normalised cross-correlation with an adaptive
template size (grown until the predicted least-squares precision from the texture, Förstner
1986, passes), then refined by least-squares matching (Gruen 1985: 6 affine + 2 radiometric
parameters) from the chip's pixels with the local chip-to-image affine as start. Search
window: the EO sigmas (columns sigma_X .. sigma_kappa_deg of the EO CSV) propagated to the
image, times 3; without them +-SEARCH_PX pixels. A match is rejected, with the reason, for a
chip without texture, low correlation, no convergence, a sigma above MAX_SIGMA, a match
outside the search ellipse or a template partly outside the image. With TRANSFER, images where
the chip match failed are matched from the point's best image (image-to-image LSM).</source>
            <translation type="vanished">Cada ponto de controle é projetado em cada imagem com a sua orientação exterior; o seu recorte (chip)
de controle (um GeoTIFF com o norte para cima do terreno em torno do ponto, retificado sobre o plano Z = Z_point,
nome do arquivo = id do ponto) é buscado ali por correlação cruzada normalizada com um tamanho de
modelo (template) adaptativo (aumentado até que a precisão prevista por mínimos quadrados a partir da textura, Förstner
1986, seja aceita), e então refinado por correspondência por mínimos quadrados (Gruen 1985: 6 parâmetros afins + 2 radiométricos)
a partir dos pixels do recorte, com a afinidade local recorte-imagem como valor inicial. Janela
de busca: os sigmas da EO (colunas sigma_X .. sigma_kappa_deg do CSV da EO) propagados para a
imagem, vezes 3; sem eles, +-SEARCH_PX pixels. Uma correspondência é rejeitada, com o motivo, para um
recorte sem textura, correlação baixa, ausência de convergência, um sigma acima de MAX_SIGMA, uma correspondência
fora da elipse de busca ou um modelo parcialmente fora da imagem. Com TRANSFER, as imagens em que
a correspondência do recorte falhou são correspondidas a partir da melhor imagem do ponto (LSM imagem a imagem).</translation>
        </message>
        <message>
            <source>Output: the image-observation CSV (image_id, point_id, col, row, sigma_px, type tie, empty
target_id; point_id = the control point's id), which bundleadjustment (with the control points
as ground points) and resection (with them as control points) read directly; sigma_px is the
LSM sigma, at least SIGMA_FLOOR (LSM does not see the chip's own errors). The report CSV has
one row per point and image with the status and reason; the HTML report shows the chips.</source>
            <translation type="vanished">Saída: o CSV de observações de imagem (image_id, point_id, col, row, sigma_px, type tie, target_id
vazio; point_id = o id do ponto de controle), que bundleadjustment (com os pontos de controle
como pontos de apoio) e resection (com eles como pontos de controle) leem diretamente; sigma_px é o
sigma da LSM, no mínimo SIGMA_FLOOR (a LSM não vê os erros do próprio recorte). O CSV do relatório tem
uma linha por ponto e imagem com o status e o motivo; o relatório HTML mostra os recortes.</translation>
        </message>
    </context>
    <context>
        <name>lidarphoto:makecontrolchips</name>
        <message>
            <source>Make control chips from ground photos</source>
            <translation>Criar recortes (chips) de controle a partir de fotos terrestres</translation>
        </message>
        <message>
            <source>Aerotriangulation</source>
            <translation>Aerotriangulação</translation>
        </message>
        <message>
            <source>Control chips: ground photos of surveyed points rectified at the aerial GSD</source>
            <translation>Recortes (chips) de controle: fotos terrestres de pontos levantados retificadas no GSD aéreo</translation>
        </message>
        <message>
            <source>Control chips for the automatic location of control points in aerial images (Berveglieri &amp;
Tommaselli 2014). For each surveyed point two ground photos taken from the same spot looking
down: one with the control plate over the point, one without it.</source>
            <translation>Recortes (chips) de controle para a localização automática de pontos de controle em imagens aéreas (Berveglieri &amp;
Tommaselli 2014). Para cada ponto levantado, duas fotos terrestres tomadas do mesmo local olhando para
baixo: uma com a placa de controle sobre o ponto, outra sem ela.</translation>
        </message>
        <message>
            <source>The ground camera may be a perspective or a fisheye camera (equidistant, equisolid,
orthographic or stereographic, with Brown distortion: the camera file of the camera
calibration), as the nadir fisheye of the source.</source>
            <translation>A câmera terrestre pode ser perspectiva ou olho de peixe (equidistante, de ângulo equissólido,
ortográfica ou estereográfica, com distorção de Brown: o arquivo de câmera da calibração
de câmera), como a câmera olho de peixe nadiral da fonte.</translation>
        </message>
        <message>
            <source>1. The plate (a square with an outer and an inner square edge; its centre vertically above
the point at plate height, levelled, one side along the plate azimuth) is found in the plate
photo; its eight corners are located at sub-pixel precision (edges fitted as straight lines
and intersected, the lens model removed), and the photo is resected from them (data snooping;
sigma0 and the sigmas in the report). The four quarter turns of the square are told apart by
the photo azimuth (the approximate grid azimuth of the photos' up direction, within 45
degrees).
2. The plate-free photo is matched to the plate photo by SIFT (Lowe 2004; ratio test, RANSAC
homography) and resected from the matched ground points.
3. It is rectified onto the horizontal plane Z = Z_point at the GSD, north up, centred on the
point: the chip (the plate hides the ground, hence the plate-free photo). Without a
plate-free photo, Chip from the plate photo makes it from the plate photo.</source>
            <translation>1. A placa (um quadrado com uma borda quadrada externa e uma interna; o seu centro na vertical acima
do ponto à altura da placa, nivelada, um lado ao longo do azimute da placa) é encontrada na foto
com placa; os seus oito cantos são localizados com precisão subpixel (bordas ajustadas como retas
e intersectadas, o modelo da lente removido), e a foto é orientada por resseção a partir deles (data snooping;
sigma0 e os sigmas no relatório). Os quatro quartos de volta do quadrado são distinguidos pelo
azimute da foto (o azimute de quadrícula aproximado da direção para cima das fotos, dentro de 45
graus).
2. A foto sem placa é correspondida à foto com placa por SIFT (Lowe 2004; teste de razão, homografia
RANSAC) e orientada por resseção a partir dos pontos do terreno correspondidos.
3. Ela é retificada sobre o plano horizontal Z = Z_point no GSD, com o norte para cima, centrada no
ponto: o recorte (a placa esconde o terreno, daí a foto sem placa). Sem uma
foto sem placa, Recorte a partir da foto com placa o gera a partir da foto com placa.</translation>
        </message>
        <message>
            <source>Ground points: the ground-point CSV of the bundle adjustment (point_id, X, Y, Z, role; every
point gets a chip, whatever its role) in the mapping CRS. Photos: a ground-photo table
(point_id, plate_photo, free_photo, and optional photo_azimuth_deg, plate_azimuth_deg), or
files / folders searched by name:
&lt;point_id&gt;&lt;plate suffix&gt;.&lt;ext&gt; and &lt;point_id&gt;&lt;free suffix&gt;.&lt;ext&gt;.</source>
            <translation>Pontos de apoio: o CSV de pontos de apoio do ajustamento por feixes de raios (point_id, X, Y, Z, role; todo
ponto recebe um recorte, qualquer que seja a sua função) no SRC de mapeamento. Fotos: uma tabela de fotos terrestres
(point_id, plate_photo, free_photo, e opcionalmente photo_azimuth_deg, plate_azimuth_deg), ou
arquivos / pastas buscados pelo nome:
&lt;point_id&gt;&lt;plate suffix&gt;.&lt;ext&gt; e &lt;point_id&gt;&lt;free suffix&gt;.&lt;ext&gt;.</translation>
        </message>
        <message>
            <source>Output folder: &lt;point_id&gt;.tif per chip (float32 grey, nodata -9999, the geotransform puts the
point at its X, Y: the chip's centre) and the report control_chips.csv / .json (per point:
status and reason, corners found, corner sigmas, resection sigma0 and sigmas, SIFT matches and
inliers). A point that fails (plate not found, only one square, ambiguous, resection sigma0
too large, too few SIFT matches, chip partly outside the photo) gets its reason and no chip;
the others are written.</source>
            <translation>Pasta de saída: &lt;point_id&gt;.tif por recorte (float32 em tons de cinza, nodata -9999, a geotransformação põe o
ponto no seu X, Y: o centro do recorte) e o relatório control_chips.csv / .json (por ponto:
status e motivo, cantos encontrados, sigmas dos cantos, sigma0 e sigmas da resseção, correspondências SIFT e
inliers). Um ponto que falha (placa não encontrada, apenas um quadrado, ambíguo, sigma0 da resseção
grande demais, poucas correspondências SIFT, recorte parcialmente fora da foto) recebe o seu motivo e nenhum recorte;
os demais são gravados.</translation>
        </message>
        <message>
            <source>Ground points (CSV)</source>
            <translation>Pontos de apoio (CSV)</translation>
        </message>
        <message>
            <source>point_id, X, Y, Z, role (the bundle adjustment's table)</source>
            <translation>point_id, X, Y, Z, role (a tabela do ajustamento por feixes de raios)</translation>
        </message>
        <message>
            <source>CSV files (*.csv *.txt)</source>
            <translation>Arquivos CSV (*.csv *.txt)</translation>
        </message>
        <message>
            <source>Mapping CRS of the points</source>
            <translation>SRC de mapeamento dos pontos</translation>
        </message>
        <message>
            <source>e.g. EPSG:31983</source>
            <translation>por exemplo, EPSG:31983</translation>
        </message>
        <message>
            <source>Ground camera (JSON)</source>
            <translation>Câmera terrestre (JSON)</translation>
        </message>
        <message>
            <source>perspective or fisheye (as written by calibratecamera)</source>
            <translation>perspectiva ou olho de peixe (como gravada por calibratecamera)</translation>
        </message>
        <message>
            <source>JSON files (*.json)</source>
            <translation>Arquivos JSON (*.json)</translation>
        </message>
        <message>
            <source>Ground-photo table (CSV)</source>
            <translation>Tabela de fotos terrestres (CSV)</translation>
        </message>
        <message>
            <source>point_id, plate_photo, free_photo; else PHOTOS are searched by name</source>
            <translation>point_id, plate_photo, free_photo; caso contrário, PHOTOS são buscadas pelo nome</translation>
        </message>
        <message>
            <source>Ground photos (files or folders)</source>
            <translation>Fotos terrestres (arquivos ou pastas)</translation>
        </message>
        <message>
            <source>searched by name when no table is given</source>
            <translation>buscadas pelo nome quando nenhuma tabela é dada</translation>
        </message>
        <message>
            <source>Plate photo name suffix</source>
            <translation>Sufixo do nome da foto com placa</translation>
        </message>
        <message>
            <source>Plate-free photo name suffix</source>
            <translation>Sufixo do nome da foto sem placa</translation>
        </message>
        <message>
            <source>Plate outer side</source>
            <translation>Lado externo da placa</translation>
        </message>
        <message>
            <source>Plate inner side</source>
            <translation>Lado interno da placa</translation>
        </message>
        <message>
            <source>Plate height above the point</source>
            <translation>Altura da placa acima do ponto</translation>
        </message>
        <message>
            <source>Plate side azimuth (grid)</source>
            <translation>Azimute do lado da placa (quadrícula)</translation>
        </message>
        <message>
            <source>Photo up azimuth (grid, +-45)</source>
            <translation>Azimute do topo da foto (quadrícula, +-45)</translation>
        </message>
        <message>
            <source>Chip GSD (the aerial images')</source>
            <translation>GSD do recorte (o das imagens aéreas)</translation>
        </message>
        <message>
            <source>Chip size</source>
            <translation>Tamanho do recorte</translation>
        </message>
        <message>
            <source>Largest resection sigma0</source>
            <translation>Maior sigma0 da resseção</translation>
        </message>
        <message>
            <source>Corner sigma (0 = from the line fits)</source>
            <translation>Sigma dos cantos (0 = a partir dos ajustes das retas)</translation>
        </message>
        <message>
            <source>SIFT ratio test</source>
            <translation>Teste de razão do SIFT</translation>
        </message>
        <message>
            <source>RANSAC threshold</source>
            <translation>Limiar do RANSAC</translation>
        </message>
        <message>
            <source>Fewest SIFT inliers</source>
            <translation>Mínimo de inliers do SIFT</translation>
        </message>
        <message>
            <source>Chip from the plate photo when no plate-free photo</source>
            <translation>Recorte a partir da foto com placa quando não houver foto sem placa</translation>
        </message>
        <message>
            <source>Output folder</source>
            <translation>Pasta de saída</translation>
        </message>
        <message>
            <source>Chips written</source>
            <translation>Recortes gravados</translation>
        </message>
        <message>
            <source>Points without a chip</source>
            <translation>Pontos sem recorte</translation>
        </message>
        <message>
            <source>Image matching</source>
            <translation type="vanished">Correspondência de imagens</translation>
        </message>
    </context>
    <context>
        <name>lidarphoto:monoplot</name>
        <message>
            <source>Monoplot image points and lines on a LiDAR DSM</source>
            <translation>Monorrestituir pontos e linhas da imagem sobre um MDS LiDAR</translation>
        </message>
        <message>
            <source>Orthophotos</source>
            <translation>Ortofotos</translation>
        </message>
        <message>
            <source>3D points and lines from one oriented image and a LiDAR DSM</source>
            <translation>pontos e linhas 3D a partir de uma imagem orientada e de um MDS LiDAR</translation>
        </message>
        <message>
            <source>Monoplotting (dos Santos, Dal Poz &amp; Dalmolin 2010): the ray of each image point is
intersected with the LiDAR surface. The camera may be perspective or fisheye (equidistant,
equisolid-angle, orthographic, stereographic, with its Brown correction): the ray is the
one of the camera's own projection. Direct (Dal Poz 1991): the ray walks the DSM's cells in
order from the camera and meets the two triangles of each cell in the determinant form of
Eqs. 6-10; the first face hit is the visible point (occlusion). Makarovic: the classical
iteration height -&gt; position -&gt; height.</source>
            <translation>Monorrestituição (dos Santos, Dal Poz &amp; Dalmolin 2010): o raio de cada ponto da imagem é
intersectado com a superfície LiDAR. A câmera pode ser perspectiva ou olho de peixe
(equidistante, equissólida, ortográfica, estereográfica, com sua correção de Brown): o raio é o
da própria projeção da câmera. Direto (Dal Poz 1991): o raio percorre as células do MDS em ordem
a partir da câmera e encontra os dois triângulos de cada célula na forma de determinantes das
Eqs. 6-10; a primeira face atingida é o ponto visível (oclusão). Makarovic: a iteração clássica
altura -&gt; posição -&gt; altura.</translation>
        </message>
        <message>
            <source>Observations: the image-observation CSV of the picking dock (image_id, point_id, col, row,
sigma_px, type, target_id). Rows of type line with the same image and target_id form one 3D
line (vertices in file order; line step adds points every so many pixels along it); other
rows are points (their target_id is not used). With a plane table, rows of type tie or paper
are intersected with their roof plane (target_id) instead.</source>
            <translation>Observações: o CSV de observações de imagem do painel de medição (image_id, point_id, col, row,
sigma_px, type, target_id). Linhas do tipo line com a mesma imagem e o mesmo target_id formam
uma linha 3D (vértices na ordem do arquivo; o passo ao longo das linhas acrescenta pontos a
cada tantos pixels); as outras linhas são pontos (o seu target_id não é usado). Com uma tabela
de planos, as linhas do tipo tie ou paper são, em vez disso, intersectadas com o seu plano de
telhado (target_id).</translation>
        </message>
        <message>
            <source>DSM: a raster, or a LAS/LAZ rasterised at cell size (highest return per cell, gaps filled;
optionally saved). A DSM in another CRS than the mapping CRS of the exterior orientation is
resampled into it, heights transformed too (DSM CRS supplies the CRS when the file has none,
or replaces it); when PROJ lacks a grid for that (e.g. a geoid), the run is refused: install
the grid, or give the DSM's CRS with ellipsoidal heights as DSM CRS.</source>
            <translation>MDS: um raster, ou um LAS/LAZ rasterizado no tamanho de célula (o retorno mais alto por célula,
lacunas preenchidas; opcionalmente salvo). Um MDS em um SRC diferente do SRC de mapeamento da
orientação exterior é reamostrado nele, com as alturas também transformadas (SRC do MDS fornece
o SRC quando o arquivo não tem nenhum, ou o substitui); quando o PROJ não tem uma grade para
isso (por exemplo, um geoide), a execução é recusada: instale a grade, ou informe como SRC do
MDS o SRC do MDS com alturas elipsoidais.</translation>
        </message>
        <message>
            <source>Each point carries a 3x3 covariance from the image sigma, the EO sigmas (X, Y, Z in m;
omega, phi, kappa in degrees) and the DSM height sigma, and a status: ok, grazing (ray meets
the face at less than the minimum angle), outside (the ray leaves the DSM), nodata (it crosses
a hole first), no_orientation (image not in the EO table), not_converged (Makarovic),
parallel / unknown_plane (planes), out_of_field (the point lies beyond a fisheye
projection's field: no ray).</source>
            <translation>Cada ponto traz uma covariância 3x3 a partir do desvio-padrão da imagem, dos desvios-padrão da
OE (X, Y, Z em m; omega, phi, kappa em graus) e do desvio-padrão da altura do MDS, e um estado:
ok, grazing (o raio encontra a face com ângulo menor que o mínimo), outside (o raio sai do
MDS), nodata (ele cruza primeiro um buraco), no_orientation (imagem ausente da tabela de OE),
not_converged (Makarovic), parallel / unknown_plane (planos), out_of_field (o ponto está além do
campo de uma projeção olho de peixe: sem raio).</translation>
        </message>
        <message>
            <source>Image observations (CSV)</source>
            <translation>Observações de imagem (CSV)</translation>
        </message>
        <message>
            <source>CSV files (*.csv *.txt)</source>
            <translation>Arquivos CSV (*.csv *.txt)</translation>
        </message>
        <message>
            <source>Camera (JSON)</source>
            <translation>Câmera (JSON)</translation>
        </message>
        <message>
            <source>JSON files (*.json)</source>
            <translation>Arquivos JSON (*.json)</translation>
        </message>
        <message>
            <source>Exterior orientation (CSV)</source>
            <translation>Orientação exterior (CSV)</translation>
        </message>
        <message>
            <source>DSM (raster, or LAS/LAZ)</source>
            <translation>MDS (raster, ou LAS/LAZ)</translation>
        </message>
        <message>
            <source>DSM (*.tif *.tiff *.img *.vrt *.asc *.las *.laz *.LAS *.LAZ)</source>
            <translation>MDS (*.tif *.tiff *.img *.vrt *.asc *.las *.laz *.LAS *.LAZ)</translation>
        </message>
        <message>
            <source>Roof plane table (CSV)</source>
            <translation>Tabela de planos de telhado (CSV)</translation>
        </message>
        <message>
            <source>Mapping CRS of the EO</source>
            <translation>SRC de mapeamento da OE</translation>
        </message>
        <message>
            <source>e.g. EPSG:28992</source>
            <translation>por exemplo, EPSG:28992</translation>
        </message>
        <message>
            <source>DSM CRS (overrides the file's)</source>
            <translation>SRC do MDS (substitui o do arquivo)</translation>
        </message>
        <message>
            <source>the DSM's CRS when the file has none or a wrong one; a 2D CRS takes the heights as ellipsoidal</source>
            <translation>o SRC do MDS quando o arquivo não tem nenhum ou tem um errado; um SRC 2D toma as alturas como elipsoidais</translation>
        </message>
        <message>
            <source>Method</source>
            <translation>Método</translation>
        </message>
        <message>
            <source>direct (Dal Poz, DDA)</source>
            <translation>direto (Dal Poz, DDA)</translation>
        </message>
        <message>
            <source>Makarovic iteration</source>
            <translation>iteração de Makarovic</translation>
        </message>
        <message>
            <source>DSM cell size for LAS/LAZ</source>
            <translation>Tamanho de célula do MDS para LAS/LAZ</translation>
        </message>
        <message>
            <source>DSM height sigma</source>
            <translation>Desvio-padrão da altura do MDS</translation>
        </message>
        <message>
            <source>Points along lines every (0 = end points)</source>
            <translation>Pontos ao longo das linhas a cada (0 = extremidades)</translation>
        </message>
        <message>
            <source>Minimum angle ray / face</source>
            <translation>Ângulo mínimo raio / face</translation>
        </message>
        <message>
            <source>EO sigmas: X, Y, Z, omega, phi, kappa</source>
            <translation>Desvios-padrão da OE: X, Y, Z, omega, phi, kappa</translation>
        </message>
        <message>
            <source>Monoplotted points</source>
            <translation>Pontos monorrestituídos</translation>
        </message>
        <message>
            <source>Monoplotted lines</source>
            <translation>Linhas monorrestituídas</translation>
        </message>
        <message>
            <source>Point table (CSV)</source>
            <translation>Tabela de pontos (CSV)</translation>
        </message>
        <message>
            <source>CSV files (*.csv)</source>
            <translation>Arquivos CSV (*.csv)</translation>
        </message>
        <message>
            <source>Line table</source>
            <translation>Tabela de linhas</translation>
        </message>
        <message>
            <source>DSM made from the LAS/LAZ</source>
            <translation>MDS gerado a partir do LAS/LAZ</translation>
        </message>
        <message>
            <source>Rays monoplotted</source>
            <translation>Raios monorrestituídos</translation>
        </message>
        <message>
            <source>Rays with a 3D point</source>
            <translation>Raios com um ponto 3D</translation>
        </message>
        <message>
            <source>Monoplotting (dos Santos, Dal Poz &amp; Dalmolin 2010): the ray of each image point is
intersected with the LiDAR surface. Direct (Dal Poz 1991): the ray walks the DSM's cells in
order from the camera and meets the two triangles of each cell in the determinant form of
Eqs. 6-10; the first face hit is the visible point (occlusion). Makarovic: the classical
iteration height -&gt; position -&gt; height.</source>
            <translation type="vanished">Monorrestituição (dos Santos, Dal Poz &amp; Dalmolin 2010): o raio de cada ponto da imagem é
intersectado com a superfície LiDAR. Direto (Dal Poz 1991): o raio percorre as células do MDS
em ordem a partir da câmera e encontra os dois triângulos de cada célula na forma de
determinantes das Eqs. 6-10; a primeira face atingida é o ponto visível (oclusão). Makarovic: a
iteração clássica altura -&gt; posição -&gt; altura.</translation>
        </message>
        <message>
            <source>Each point carries a 3x3 covariance from the image sigma, the EO sigmas (X, Y, Z in m;
omega, phi, kappa in degrees) and the DSM height sigma, and a status: ok, grazing (ray meets
the face at less than the minimum angle), outside (the ray leaves the DSM), nodata (it crosses
a hole first), no_orientation (image not in the EO table), not_converged (Makarovic),
parallel / unknown_plane (planes).</source>
            <translation type="vanished">Cada ponto traz uma covariância 3x3 a partir do desvio-padrão da imagem, dos desvios-padrão da
OE (X, Y, Z em m; omega, phi, kappa em graus) e do desvio-padrão da altura do MDS, e um estado:
ok, grazing (o raio encontra a face com ângulo menor que o mínimo), outside (o raio sai do
MDS), nodata (ele cruza primeiro um buraco), no_orientation (imagem ausente da tabela de OE),
not_converged (Makarovic), parallel / unknown_plane (planos).</translation>
        </message>
        <message>
            <source>Monoplotting</source>
            <translation type="vanished">Monorrestituição</translation>
        </message>
    </context>
    <context>
        <name>lidarphoto:orthomosaic</name>
        <message>
            <source>Orthomosaic (seamlines, feathering, occlusion-aware)</source>
            <translation>Ortomosaico (linhas de costura, suavização das bordas, com tratamento de oclusões)</translation>
        </message>
        <message>
            <source>Orthophotos</source>
            <translation>Ortofotos</translation>
        </message>
        <message>
            <source>orthophotos into one mosaic, each cell from the image that sees it best</source>
            <translation>ortofotos em um único mosaico, cada célula a partir da imagem que melhor a vê</translation>
        </message>
        <message>
            <source>Every cell of the mosaic takes the orthophoto that sees it most nadir (the smallest angle
between the vertical and the ray to the camera's perspective centre, kept in the metadata of
the orthophotos Orthorectify writes) or, with method centre, the one whose image centre is
nearest. Only orthophotos with data at the cell compete: with true orthophotos, ground
occluded in one image is filled from another that sees it.</source>
            <translation>Cada célula do mosaico recebe a ortofoto que a vê mais perto do nadir (o menor ângulo entre a
vertical e o raio até o centro perspectivo da câmera, guardado nos metadados das ortofotos que
Ortorretificar grava) ou, com o método centre, aquela cujo centro da imagem está mais próximo.
Apenas as ortofotos com dados na célula concorrem: com ortofotos verdadeiras, o terreno oculto
em uma imagem é preenchido a partir de outra que o vê.</translation>
        </message>
        <message>
            <source>Feathering blends the images across the seamlines over the given width (cells), linearly,
centred on the seamline; 0 leaves hard seams.</source>
            <translation>A suavização das bordas (feathering) mistura as imagens através das linhas de costura na
largura informada (células), linearmente, centrada na linha de costura; 0 deixa costuras
abruptas.</translation>
        </message>
        <message>
            <source>## Inputs
Orthophotos: GeoTIFFs of one CRS and cell size, aligned on multiples of it (Orthorectify
with one GSD makes them so, from perspective or fisheye images alike), or folders of them.</source>
            <translation>## Entradas
Ortofotos: GeoTIFFs de um mesmo SRC e tamanho de célula, alinhados em múltiplos dele
(Ortorretificar com um único GSD os produz assim, de imagens perspectivas ou olho de peixe), ou
pastas com eles.</translation>
        </message>
        <message>
            <source>## Outputs
The mosaic (GeoTIFF: tiled, compressed, overviews, internal mask), and the seamline polygons:
the region each image fills, as a layer and as a CSV (image_id, cells, area, WKT
MultiPolygon in the mosaic's CRS).</source>
            <translation>## Saídas
O mosaico (GeoTIFF: em blocos, comprimido, com visões gerais e máscara interna) e os polígonos
das linhas de costura: a região que cada imagem preenche, como camada e como CSV (image_id,
cells, area, WKT MultiPolygon no SRC do mosaico).</translation>
        </message>
        <message>
            <source>Orthophotos (files or folders)</source>
            <translation>Ortofotos (arquivos ou pastas)</translation>
        </message>
        <message>
            <source>Image chosen per cell</source>
            <translation>Imagem escolhida por célula</translation>
        </message>
        <message>
            <source>most nadir view</source>
            <translation>visada mais próxima do nadir</translation>
        </message>
        <message>
            <source>nearest image centre</source>
            <translation>centro de imagem mais próximo</translation>
        </message>
        <message>
            <source>Feathering width across seamlines (0 = none)</source>
            <translation>Largura da suavização através das linhas de costura (0 = nenhuma)</translation>
        </message>
        <message>
            <source>GeoTIFF compression</source>
            <translation>Compressão do GeoTIFF</translation>
        </message>
        <message>
            <source>deflate and zstd at their fastest level (files about 15 % larger than at the default level); jpeg is lossy and only for 8-bit images</source>
            <translation>deflate e zstd no seu nível mais rápido (arquivos cerca de 15 % maiores que no nível padrão); jpeg tem perdas e serve apenas para imagens de 8 bits</translation>
        </message>
        <message>
            <source>DEFLATE (lossless, level 1: fast)</source>
            <translation>DEFLATE (sem perdas, nível 1: rápido)</translation>
        </message>
        <message>
            <source>ZSTD (lossless, level 1)</source>
            <translation>ZSTD (sem perdas, nível 1)</translation>
        </message>
        <message>
            <source>LZW (lossless)</source>
            <translation>LZW (sem perdas)</translation>
        </message>
        <message>
            <source>JPEG (lossy, quality 90; 8-bit images)</source>
            <translation>JPEG (com perdas, qualidade 90; imagens de 8 bits)</translation>
        </message>
        <message>
            <source>none</source>
            <translation>nenhuma</translation>
        </message>
        <message>
            <source>Orthomosaic</source>
            <translation>Ortomosaico</translation>
        </message>
        <message>
            <source>Seamlines (region of each image)</source>
            <translation>Linhas de costura (região de cada imagem)</translation>
        </message>
        <message>
            <source>Seamline table (CSV)</source>
            <translation>Tabela das linhas de costura (CSV)</translation>
        </message>
        <message>
            <source>CSV files (*.csv)</source>
            <translation>Arquivos CSV (*.csv)</translation>
        </message>
        <message>
            <source>Orthophotos mosaicked</source>
            <translation>Ortofotos no mosaico</translation>
        </message>
        <message>
            <source>Share of the mosaic's cells with data</source>
            <translation>Fração das células do mosaico com dados</translation>
        </message>
        <message>
            <source>## Inputs
Orthophotos: GeoTIFFs of one CRS and cell size, aligned on multiples of it (Orthorectify
with one GSD makes them so), or folders of them.</source>
            <translation type="vanished">## Entradas
Ortofotos: GeoTIFFs de um mesmo SRC e tamanho de célula, alinhados em múltiplos dele
(Ortorretificar com um único GSD os produz assim), ou pastas com eles.</translation>
        </message>
    </context>
    <context>
        <name>lidarphoto:orthorectify</name>
        <message>
            <source>Orthorectify images on a LiDAR DSM (true orthophotos)</source>
            <translation>Ortorretificar imagens sobre um MDS LiDAR (ortofotos verdadeiras)</translation>
        </message>
        <message>
            <source>Orthophotos</source>
            <translation>Ortofotos</translation>
        </message>
        <message>
            <source>orthophotos of oriented frame images on a LiDAR DSM or DTM</source>
            <translation>ortofotos de imagens de quadro orientadas sobre um MDS ou MDT LiDAR</translation>
        </message>
        <message>
            <source>Each image is resampled onto a north-up grid of the mapping CRS through the surface: the
height of every output cell comes from the DSM (or DTM) and its image position from the
camera (lens model included) and the exterior orientation, by the rigorous chain of the
toolbox (local ENU frame reached through ECEF, so the map projection's scale and the Earth's
curvature are not neglected). The camera may be perspective or fisheye (equidistant,
equisolid-angle, orthographic, stereographic, with its Brown correction, as Calibrate camera
writes it): a fisheye maps the angle off its axis, and ground beyond its field is no data.</source>
            <translation>Cada imagem é reamostrada em uma grade orientada ao norte do SRC de mapeamento através da
superfície: a altura de cada célula de saída vem do MDS (ou MDT) e a sua posição na imagem vem
da câmera (modelo de lente incluído) e da orientação exterior, pela cadeia rigorosa do kit de
ferramentas (referencial local ENU alcançado através do ECEF, de modo que a escala da projeção
cartográfica e a curvatura da Terra não são desprezadas). A câmera pode ser perspectiva ou olho
de peixe (equidistante, equissólida, ortográfica, estereográfica, com sua correção de Brown, como
Calibrar câmera a escreve): uma olho de peixe mapeia o ângulo fora do seu eixo, e o terreno além
do seu campo fica sem dado.</translation>
        </message>
        <message>
            <source>With True orthophoto, ground hidden from the camera (behind buildings, under trees and
overhangs) is found by tracing the ray from the camera to every cell through the DSM (as
monoplotting does) and left as no data; Orthomosaic then fills it from other images.</source>
            <translation>Com Ortofoto verdadeira, o terreno oculto à câmera (atrás de edifícios, sob árvores e beirais)
é encontrado traçando o raio da câmera até cada célula através do MDS (como faz a
monorrestituição) e deixado sem dados; o Ortomosaico o preenche então a partir de outras
imagens.</translation>
        </message>
        <message>
            <source>## Inputs
Images: image files, or folders of them (tif, tiff, jpg, png, jp2, img); each image is
matched to the row of the EO table whose image_id is its file name without extension. Every
image must have the camera's size. DSM: a raster (a layer or a file), or a LAS/LAZ cloud
rasterised at DSM cell size (highest return per cell, gaps filled). A DSM in another CRS is
resampled into the mapping CRS, heights transformed too; when PROJ cannot (a missing geoid
grid) the run stops with PROJ's reason.</source>
            <translation>## Entradas
Imagens: arquivos de imagem, ou pastas com eles (tif, tiff, jpg, png, jp2, img); cada imagem é
associada à linha da tabela de OE cujo image_id é o nome do seu arquivo sem extensão. Toda
imagem deve ter o tamanho da câmera. MDS: um raster (uma camada ou um arquivo), ou uma nuvem
LAS/LAZ rasterizada no tamanho de célula do MDS (o retorno mais alto por célula, lacunas
preenchidas). Um MDS em outro SRC é reamostrado no SRC de mapeamento, com as alturas também
transformadas; quando o PROJ não consegue (falta a grade de um geoide), a execução para com o
motivo dado pelo PROJ.</translation>
        </message>
        <message>
            <source>## Output
One GeoTIFF per image, &lt;image_id&gt;_ortho.tif in the output folder: the image's bands and type,
tiled, compressed (DEFLATE by default), with overviews, the CRS and an internal mask (no data
outside the image, beyond the DSM and, for true orthophotos, where occluded). Its metadata keep the
perspective centre, which Orthomosaic uses. GSD 0 takes the images' nadir GSD (the median
over the images, 2 significant digits); the grids are aligned on multiples of the GSD. The
extent is each image's footprint on the DSM, or the extent given (xmin, ymin, xmax, ymax).
Nothing is written when an input is wrong; the files appear together when all are done.</source>
            <translation>## Saída
Um GeoTIFF por imagem, &lt;image_id&gt;_ortho.tif na pasta de saída: as bandas e o tipo da imagem, em
blocos, comprimido (DEFLATE por padrão), com visões gerais, o SRC e uma máscara interna (sem
dados fora da imagem, além do MDS e, nas ortofotos verdadeiras, onde há oclusão). Os seus
metadados guardam o centro perspectivo, que o Ortomosaico usa. GSD 0 toma o GSD no nadir das
imagens (a mediana sobre as imagens, 2 algarismos significativos); as grades são alinhadas em
múltiplos do GSD. A extensão é a projeção de cada imagem sobre o MDS, ou a extensão informada
(xmin, ymin, xmax, ymax). Nada é gravado quando uma entrada está errada; os arquivos aparecem
juntos quando todos estão prontos.</translation>
        </message>
        <message>
            <source>Camera (JSON)</source>
            <translation>Câmera (JSON)</translation>
        </message>
        <message>
            <source>JSON files (*.json)</source>
            <translation>Arquivos JSON (*.json)</translation>
        </message>
        <message>
            <source>Exterior orientation (CSV)</source>
            <translation>Orientação exterior (CSV)</translation>
        </message>
        <message>
            <source>CSV files (*.csv *.txt)</source>
            <translation>Arquivos CSV (*.csv *.txt)</translation>
        </message>
        <message>
            <source>Images (files or folders)</source>
            <translation>Imagens (arquivos ou pastas)</translation>
        </message>
        <message>
            <source>image files, or folders whose images are all taken</source>
            <translation>arquivos de imagem, ou pastas cujas imagens são todas tomadas</translation>
        </message>
        <message>
            <source>DSM or DTM (raster, or LAS/LAZ)</source>
            <translation>MDS ou MDT (raster, ou LAS/LAZ)</translation>
        </message>
        <message>
            <source>a raster (the file of a raster layer) or a LAS/LAZ cloud</source>
            <translation>um raster (o arquivo de uma camada raster) ou uma nuvem LAS/LAZ</translation>
        </message>
        <message>
            <source>DSM (*.tif *.tiff *.img *.vrt *.asc *.las *.laz *.LAS *.LAZ)</source>
            <translation>MDS (*.tif *.tiff *.img *.vrt *.asc *.las *.laz *.LAS *.LAZ)</translation>
        </message>
        <message>
            <source>Mapping CRS of the EO</source>
            <translation>SRC de mapeamento da OE</translation>
        </message>
        <message>
            <source>e.g. EPSG:28992</source>
            <translation>por exemplo, EPSG:28992</translation>
        </message>
        <message>
            <source>DSM CRS (if the file has none)</source>
            <translation>SRC do MDS (se o arquivo não tiver nenhum)</translation>
        </message>
        <message>
            <source>DSM cell size for LAS/LAZ</source>
            <translation>Tamanho de célula do MDS para LAS/LAZ</translation>
        </message>
        <message>
            <source>Output cell size (0 = image GSD)</source>
            <translation>Tamanho da célula de saída (0 = GSD da imagem)</translation>
        </message>
        <message>
            <source>Extent xmin,ymin,xmax,ymax (empty = footprint)</source>
            <translation>Extensão xmin,ymin,xmax,ymax (vazio = projeção da imagem no terreno)</translation>
        </message>
        <message>
            <source>Resampling</source>
            <translation>Reamostragem</translation>
        </message>
        <message>
            <source>True orthophoto (occluded ground = no data)</source>
            <translation>Ortofoto verdadeira (terreno ocluso = sem dados)</translation>
        </message>
        <message>
            <source>Occlusion tolerance along the ray</source>
            <translation>Tolerância de oclusão ao longo do raio</translation>
        </message>
        <message>
            <source>GeoTIFF compression</source>
            <translation>Compressão do GeoTIFF</translation>
        </message>
        <message>
            <source>deflate and zstd at their fastest level (files about 15 % larger than at the default level); jpeg is lossy and only for 8-bit images</source>
            <translation>deflate e zstd no seu nível mais rápido (arquivos cerca de 15 % maiores que no nível padrão); jpeg tem perdas e serve apenas para imagens de 8 bits</translation>
        </message>
        <message>
            <source>DEFLATE (lossless, level 1: fast)</source>
            <translation>DEFLATE (sem perdas, nível 1: rápido)</translation>
        </message>
        <message>
            <source>ZSTD (lossless, level 1)</source>
            <translation>ZSTD (sem perdas, nível 1)</translation>
        </message>
        <message>
            <source>LZW (lossless)</source>
            <translation>LZW (sem perdas)</translation>
        </message>
        <message>
            <source>JPEG (lossy, quality 90; 8-bit images)</source>
            <translation>JPEG (com perdas, qualidade 90; imagens de 8 bits)</translation>
        </message>
        <message>
            <source>none</source>
            <translation>nenhuma</translation>
        </message>
        <message>
            <source>Output folder</source>
            <translation>Pasta de saída</translation>
        </message>
        <message>
            <source>Orthophotos written</source>
            <translation>Ortofotos gravadas</translation>
        </message>
        <message>
            <source>Cell size used</source>
            <translation>Tamanho de célula usado</translation>
        </message>
        <message>
            <source>Share of cells occluded (true orthophotos)</source>
            <translation>Fração das células oclusas (ortofotos verdadeiras)</translation>
        </message>
        <message>
            <source>Each image is resampled onto a north-up grid of the mapping CRS through the surface: the
height of every output cell comes from the DSM (or DTM) and its image position from the
camera (lens model included) and the exterior orientation, by the rigorous chain of the
toolbox (local ENU frame reached through ECEF, so the map projection's scale and the Earth's
curvature are not neglected).</source>
            <translation type="vanished">Cada imagem é reamostrada em uma grade orientada ao norte do SRC de mapeamento através da
superfície: a altura de cada célula de saída vem do MDS (ou MDT) e a sua posição na imagem vem
da câmera (modelo de lente incluído) e da orientação exterior, pela cadeia rigorosa do kit de
ferramentas (referencial local ENU alcançado através do ECEF, de modo que a escala da projeção
cartográfica e a curvatura da Terra não são desprezadas).</translation>
        </message>
    </context>
    <context>
        <name>lidarphoto:resection</name>
        <message>
            <source>Space resection from points and lines</source>
            <translation>Resseção espacial a partir de pontos e linhas</translation>
        </message>
        <message>
            <source>Aerotriangulation</source>
            <translation>Aerotriangulação</translation>
        </message>
        <message>
            <source>exterior orientation of single images from control points and straight lines</source>
            <translation>orientação exterior de imagens isoladas a partir de pontos de controle e retas</translation>
        </message>
        <message>
            <source>Orients each image on its own from control points (collinearity) and straight lines: image
lines matched to 3D lines, such as the ridge, hip and valley lines of Create LiDAR control
points and lines, or lines monoplotted on another image (dos Santos, Dal Poz &amp; Dalmolin 2010).
No approximate orientation is needed: a global search over the rotation with the position
eliminated in closed form (Hesch &amp; Roumeliotis 2011; Mirzaei &amp; Roumeliotis 2011) gives the
start, OpenCV's solvePnP another when there are four or more points, and the one that fits
best starts the rigorous adjustment. The camera may be perspective or, for control points,
fisheye (equidistant, equisolid-angle, orthographic, stereographic, Brown added: its own
projection and rays); straight lines need a perspective camera (line rows with a fisheye
camera are refused).</source>
            <translation>Orienta cada imagem isoladamente a partir de pontos de controle (colinearidade) e de retas:
linhas da imagem associadas a linhas 3D, como as linhas de cumeeira, espigão e rincão de Criar
pontos e linhas de controle LiDAR, ou linhas monorrestituídas em outra imagem (dos Santos, Dal
Poz &amp; Dalmolin 2010). Nenhuma orientação aproximada é necessária: uma busca global sobre a
rotação, com a posição eliminada em forma fechada (Hesch &amp; Roumeliotis 2011; Mirzaei &amp;
Roumeliotis 2011), dá o ponto de partida, o solvePnP do OpenCV dá outro quando há quatro ou
mais pontos, e o que melhor se ajusta inicia o ajustamento rigoroso. A câmera pode ser
perspectiva ou, para pontos de controle, olho de peixe (equidistante, equissólida, ortográfica,
estereográfica, com Brown somado: a sua própria projeção e os seus raios); as retas precisam
de uma câmera perspectiva (linhas do tipo line com uma câmera olho de peixe são recusadas).</translation>
        </message>
        <message>
            <source>Line models: coplanarity (every point measured on an image line lies on the projected 3D
line; no parametrisation, the default) or the equivalent-planes model of Tommaselli &amp; Tozzi
(1996) as used by dos Santos et al. (2010), in its two parametrisations y = a x + b and
x = a* y + b*, chosen per line by its direction. Both give the same estimate at convergence;
they differ in how far from the solution they converge. The pixel sigmas and the covariance
of the control (LCP and line tables, or sx, sy, sz) are propagated; the focal length and the
principal point can be refined when the control has depth.</source>
            <translation>Modelos de linha: coplanaridade (todo ponto medido sobre uma linha da imagem está sobre a linha
3D projetada; sem parametrização, o padrão) ou o modelo de planos equivalentes de Tommaselli &amp;
Tozzi (1996), como usado por dos Santos et al. (2010), nas suas duas parametrizações y = a x +
b e x = a* y + b*, escolhida para cada linha pela sua direção. Ambos dão a mesma estimativa na
convergência; diferem em quão longe da solução convergem. Os desvios-padrão em pixels e a
covariância do controle (tabelas de LCPs e de linhas, ou sx, sy, sz) são propagados; a
distância focal e o ponto principal podem ser refinados quando o controle tem profundidade.</translation>
        </message>
        <message>
            <source>Observations: the image-observation CSV (image_id, point_id, col, row, sigma_px, type,
target_id). Rows of type line with the same image and target_id are one image line (two or
more points: its ends); lcp rows are control points and check rows check points (target_id:
the control point id); control rows (as Locate control points writes them) are the control
point point_id, and tie and paper rows whose point_id is a control point are control points
too. LINE_OBSERVATIONS may hold the line rows in a second file.</source>
            <translation>Observações: o CSV de observações de imagem (image_id, point_id, col, row, sigma_px, type,
target_id). Linhas do tipo line com a mesma imagem e o mesmo target_id são uma linha da imagem
(dois ou mais pontos: as suas extremidades); linhas lcp são pontos de controle e linhas check
são pontos de verificação (target_id: o identificador do ponto de controle); linhas control
(como Localizar pontos de controle as escreve) são o ponto de controle point_id, e linhas tie e
paper cujo point_id é um ponto de controle também são pontos de controle. LINE_OBSERVATIONS pode
conter as linhas do tipo line em um segundo arquivo.</translation>
        </message>
        <message>
            <source>Control points: point_id,X,Y,Z[,sx,sy,sz] or the LCP table. Control lines: the line table of
Create LiDAR control points and lines, a segment table id,x1,y1,z1,x2,y2,z2[,sigma_start,
sigma_end], or the line table of Monoplot. APPROX_EO (an EO table) replaces the automatic
start; with APPROX_EO_SIGMAS it is weighted as observations (the source's weighted
constraints).</source>
            <translation>Pontos de controle: point_id,X,Y,Z[,sx,sy,sz] ou a tabela de LCPs. Linhas de controle: a tabela
de linhas de Criar pontos e linhas de controle LiDAR, uma tabela de segmentos
id,x1,y1,z1,x2,y2,z2[,sigma_start,sigma_end] ou a tabela de linhas de Monorrestituir. APPROX_EO
(uma tabela de OE) substitui o ponto de partida automático; com APPROX_EO_SIGMAS, ela é
ponderada como observações (as injunções ponderadas da fonte).</translation>
        </message>
        <message>
            <source>Statistics per image: sigma0, the global chi-square test (the statistic against the
one-sided 5 % critical value, as the source reports it, and the two-sided test), the
standard deviations and correlations of the six parameters, Baarda's data snooping of points
and whole lines, and a diagnosis naming what the observations cannot determine (e.g. all
lines parallel).</source>
            <translation>Estatísticas por imagem: sigma0, o teste global qui-quadrado (a estatística contra o valor
crítico unilateral de 5 %, como a fonte o relata, e o teste bilateral), os desvios-padrão e as
correlações dos seis parâmetros, o data snooping de Baarda de pontos e de linhas inteiras, e um
diagnóstico que nomeia o que as observações não conseguem determinar (por exemplo, todas as
linhas paralelas).</translation>
        </message>
        <message>
            <source>Camera (JSON)</source>
            <translation>Câmera (JSON)</translation>
        </message>
        <message>
            <source>JSON files (*.json)</source>
            <translation>Arquivos JSON (*.json)</translation>
        </message>
        <message>
            <source>Image observations (CSV)</source>
            <translation>Observações de imagem (CSV)</translation>
        </message>
        <message>
            <source>points (and line points) measured in the images</source>
            <translation>pontos (e pontos de linhas) medidos nas imagens</translation>
        </message>
        <message>
            <source>CSV files (*.csv *.txt)</source>
            <translation>Arquivos CSV (*.csv *.txt)</translation>
        </message>
        <message>
            <source>Image line observations (CSV)</source>
            <translation>Observações de linhas da imagem (CSV)</translation>
        </message>
        <message>
            <source>rows of type line in a second observation file</source>
            <translation>linhas do tipo line em um segundo arquivo de observações</translation>
        </message>
        <message>
            <source>Control points (CSV)</source>
            <translation>Pontos de controle (CSV)</translation>
        </message>
        <message>
            <source>point_id,X,Y,Z[,sx,sy,sz] or the LCP table</source>
            <translation>point_id,X,Y,Z[,sx,sy,sz] ou a tabela de LCPs</translation>
        </message>
        <message>
            <source>Control lines (CSV)</source>
            <translation>Linhas de controle (CSV)</translation>
        </message>
        <message>
            <source>LiDAR line table, 3D segments (id,x1..z2) or monoplotted lines</source>
            <translation>tabela de linhas LiDAR, segmentos 3D (id,x1..z2) ou linhas monorrestituídas</translation>
        </message>
        <message>
            <source>Mapping CRS of the control</source>
            <translation>SRC de mapeamento do controle</translation>
        </message>
        <message>
            <source>projected CRS of the control points and lines (and of APPROX_EO)</source>
            <translation>SRC projetado dos pontos e linhas de controle (e de APPROX_EO)</translation>
        </message>
        <message>
            <source>Approximate exterior orientation (CSV)</source>
            <translation>Orientação exterior aproximada (CSV)</translation>
        </message>
        <message>
            <source>start values instead of the automatic start (images not in it start automatically)</source>
            <translation>valores iniciais em vez do ponto de partida automático (as imagens ausentes dela partem automaticamente)</translation>
        </message>
        <message>
            <source>Weights of the approximate EO: X, Y, Z, omega, phi, kappa</source>
            <translation>Pesos da OE aproximada: X, Y, Z, omega, phi, kappa</translation>
        </message>
        <message>
            <source>empty: start values only; given: weighted observations</source>
            <translation>vazio: apenas valores iniciais; informado: observações ponderadas</translation>
        </message>
        <message>
            <source>Images (comma separated; empty: all)</source>
            <translation>Imagens (separadas por vírgulas; vazio: todas)</translation>
        </message>
        <message>
            <source>Line model</source>
            <translation>Modelo de linha</translation>
        </message>
        <message>
            <source>coplanarity (no parametrisation)</source>
            <translation>coplanaridade (sem parametrização)</translation>
        </message>
        <message>
            <source>equivalent planes (Tommaselli &amp; Tozzi 1996)</source>
            <translation>planos equivalentes (Tommaselli &amp; Tozzi 1996)</translation>
        </message>
        <message>
            <source>Refine focal length and principal point</source>
            <translation>Refinar a distância focal e o ponto principal</translation>
        </message>
        <message>
            <source>Data snooping (Baarda)</source>
            <translation>Detecção de erros grosseiros (data snooping de Baarda)</translation>
        </message>
        <message>
            <source>Exterior orientation with sigmas (CSV)</source>
            <translation>Orientação exterior com desvios-padrão (CSV)</translation>
        </message>
        <message>
            <source>CSV files (*.csv)</source>
            <translation>Arquivos CSV (*.csv)</translation>
        </message>
        <message>
            <source>Residuals (CSV)</source>
            <translation>Resíduos (CSV)</translation>
        </message>
        <message>
            <source>Summary (HTML)</source>
            <translation>Resumo (HTML)</translation>
        </message>
        <message>
            <source>HTML files (*.html)</source>
            <translation>Arquivos HTML (*.html)</translation>
        </message>
        <message>
            <source>Images resected</source>
            <translation>Imagens com resseção</translation>
        </message>
        <message>
            <source>Largest sigma0 a-posteriori</source>
            <translation>Maior sigma0 a posteriori</translation>
        </message>
        <message>
            <source>Orients each image on its own from control points (collinearity) and straight lines: image
lines matched to 3D lines, such as the ridge, hip and valley lines of Create LiDAR control
points and lines, or lines monoplotted on another image (dos Santos, Dal Poz &amp; Dalmolin 2010).
No approximate orientation is needed: a global search over the rotation with the position
eliminated in closed form (Hesch &amp; Roumeliotis 2011; Mirzaei &amp; Roumeliotis 2011) gives the
start, OpenCV's solvePnP another when there are four or more points, and the one that fits
best starts the rigorous adjustment.</source>
            <translation type="vanished">Orienta cada imagem isoladamente a partir de pontos de controle (colinearidade) e de retas:
linhas da imagem associadas a linhas 3D, como as linhas de cumeeira, espigão e rincão de Criar
pontos e linhas de controle LiDAR, ou linhas monorrestituídas em outra imagem (dos Santos, Dal
Poz &amp; Dalmolin 2010). Nenhuma orientação aproximada é necessária: uma busca global sobre a
rotação, com a posição eliminada em forma fechada (Hesch &amp; Roumeliotis 2011; Mirzaei &amp;
Roumeliotis 2011), dá o ponto de partida, o solvePnP do OpenCV dá outro quando há quatro ou
mais pontos, e o que melhor se ajusta inicia o ajustamento rigoroso.</translation>
        </message>
        <message>
            <source>Orientation</source>
            <translation type="vanished">Orientação</translation>
        </message>
        <message>
            <source>Observations: the image-observation CSV (image_id, point_id, col, row, sigma_px, type,
target_id). Rows of type line with the same image and target_id are one image line (two or
more points: its ends); lcp rows are control points and check rows check points (target_id:
the control point id); tie and paper rows whose point_id is a control point are control
points too. LINE_OBSERVATIONS may hold the line rows in a second file.</source>
            <translation type="vanished">Observações: o CSV de observações de imagem (image_id, point_id, col, row, sigma_px, type,
target_id). Linhas do tipo line com a mesma imagem e o mesmo target_id são uma linha da imagem
(dois ou mais pontos: as suas extremidades); linhas lcp são pontos de controle e linhas check
são pontos de verificação (target_id: o identificador do ponto de controle); linhas tie e paper
cujo point_id é um ponto de controle também são pontos de controle. LINE_OBSERVATIONS pode
conter as linhas do tipo line em um segundo arquivo.</translation>
        </message>
    </context>
    <context>
        <name>lidarphoto:tiepoints</name>
        <message>
            <source>Automatic tie points</source>
            <translation>Pontos de enlace automáticos</translation>
        </message>
        <message>
            <source>Aerotriangulation</source>
            <translation>Aerotriangulação</translation>
        </message>
        <message>
            <source>tie points of overlapping images by feature matching, for the bundle adjustment</source>
            <translation>pontos de enlace de imagens sobrepostas por correspondência de feições, para o ajustamento por feixes de raios</translation>
        </message>
        <message>
            <source>Finds tie points in a block of images without an operator. Features: SIFT (Lowe 2004) or
ORB (Rublee et al. 2011, faster, less precise), detected once per image, on the image reduced
by the smallest integer factor that brings its longer side to at most Detection size (0: full
resolution; reductions by 2, 4 and 8 are made while decoding JPEGs); the keypoints are
scaled back to full-resolution pixels. SIFT keeps the Features per image of the largest
scales (Keypoints kept) among the extrema above its Contrast threshold.</source>
            <translation>Encontra pontos de enlace em um bloco de imagens sem operador. Feições: SIFT (Lowe 2004) ou
ORB (Rublee et al. 2011, mais rápido, menos preciso), detectadas uma vez por imagem, na imagem reduzida
pelo menor fator inteiro que leva o seu lado maior a no máximo Tamanho de detecção (0: resolução
completa; reduções por 2, 4 e 8 são feitas durante a decodificação de JPEGs); os pontos-chave são
reescalados para pixels da resolução completa. O SIFT mantém as Feições por imagem das maiores
escalas (Pontos-chave mantidos) entre os extremos acima do seu Limiar de contraste.</translation>
        </message>
        <message>
            <source>Pairs: with an exterior orientation and a camera, the pairs whose ground footprints (image
corners met with the plane at Mean terrain height; a fisheye image: the convex hull of 64
points a side of its border, a ray that misses the plane cut at 10 flying heights) overlap
by at least Minimum overlap of the smaller footprint; without them, each image with the
next Window images in file-name order (sequential), or all pairs. An image the EO table
lacks is paired with every image.</source>
            <translation>Pares: com uma orientação exterior e uma câmera, os pares cujas projeções no terreno (cantos da imagem
intersectados com o plano na Altura média do terreno; uma imagem olho de peixe: a envoltória
convexa de 64 pontos por lado da sua borda, um raio que não atinge o plano cortado a 10 alturas
de voo) se sobrepõem em pelo menos Sobreposição mínima da menor projeção; sem elas, cada imagem
com as próximas Janela imagens na ordem dos nomes de arquivo (sequencial), ou todos os pares.
Uma imagem ausente da tabela de EO é pareada com todas as imagens.</translation>
        </message>
        <message>
            <source>Matching: nearest neighbours in descriptor space (FLANN k-d trees for SIFT, Muja &amp; Lowe 2009;
brute force for ORB), Lowe's ratio test, a mutual check, then RANSAC on the fundamental
matrix (Fischler &amp; Bolles 1981; MAGSAC++ by default) with a threshold on the distance to the
epipolar line in full-resolution pixels. SIFT descriptors are compared as RootSIFT
(Arandjelovic &amp; Zisserman 2012) and, after the fundamental matrix, matched again along the
epipolar lines (guided matching); both are on by default. Pairs with fewer than Minimum
inliers are dropped (the pair table gives the reason). Tracks: the matches of all pairs are
merged (connected components; keypoints of one image at one position, SIFT's orientations of
one extremum, count as one); a track holding two different points of one image is dropped,
as are tracks seen in fewer than Minimum track length images.</source>
            <translation>Correspondência: vizinhos mais próximos no espaço dos descritores (árvores k-d do FLANN para SIFT, Muja &amp; Lowe 2009;
força bruta para ORB), teste de razão de Lowe, uma verificação mútua, e então RANSAC sobre a matriz
fundamental (Fischler &amp; Bolles 1981; MAGSAC++ por padrão) com um limiar sobre a distância à
linha epipolar em pixels da resolução completa. Os descritores SIFT são comparados como RootSIFT
(Arandjelovic &amp; Zisserman 2012) e, depois da matriz fundamental, associados de novo ao longo das
linhas epipolares (correspondência guiada); ambos estão ativos por padrão. Pares com menos que
Mínimo de inliers são descartados (a tabela de pares dá o motivo). Trilhas: as correspondências
de todos os pares são unidas (componentes conexas; pontos-chave de uma imagem na mesma posição,
as orientações SIFT de um mesmo extremo, contam como um só); uma trilha que contém dois pontos
diferentes de uma mesma imagem é descartada, assim como as trilhas vistas em menos imagens que
Comprimento mínimo da trilha.</translation>
        </message>
        <message>
            <source>Fisheye images (a CAMERA with a fisheye projection, Brown correction included; needed for
them, with or without EO): the fundamental matrix holds between perspective images only, so
the keypoints become the camera's rays and the RANSAC (the threshold in the same pixels) runs
on the essential matrix of the rays within 75 degrees of the axis (Nister 2004), refined by
least squares on the distances to the epipolar curves in pixels; the guided matching follows
those curves. Simulated blocks of the four fisheye projections (corners 62-65 degrees off
the axis): refined measurements 0.021-0.033 px from the truth in the median; the fundamental
matrix on the raw pixels keeps 77-85 % of the matches, 37-52 % of those beyond 400 px from
the centre.</source>
            <translation>Imagens olho de peixe (uma CAMERA com projeção olho de peixe, correção de Brown incluída;
necessária para elas, com ou sem EO): a matriz fundamental só vale entre imagens perspectivas,
por isso os pontos-chave viram os raios da câmera e o RANSAC (o limiar nos mesmos pixels) roda
sobre a matriz essencial dos raios a até 75 graus do eixo (Nister 2004), refinada por mínimos
quadrados sobre as distâncias às curvas epipolares em pixels; a correspondência guiada segue
essas curvas. Blocos simulados das quatro projeções olho de peixe (cantos a 62-65 graus do
eixo): medidas refinadas a 0,021-0,033 px da verdade na mediana; a matriz fundamental sobre os
pixels brutos mantém 77-85 % das correspondências, 37-52 % delas além de 400 px do centro.</translation>
        </message>
        <message>
            <source>Refinement (on by default; unticked, the keypoints are written as detected): least-squares
matching (Gruen 1985, 6 affine + 2 radiometric parameters) of every measurement of a track
against a 21 x 21 px template around its measurement in the track's first image (kept
fixed), in the full-resolution grey images (each read a second time, one at a time),
starting from the local affine between the two images; a match the least-squares matching
calls another point (moved more than 3 px, correlation below 0.7) is dropped, as is one it
refuses for another reason (left its window, no convergence); a measurement it cannot try
(template at the image border, no start affine) keeps the keypoint.</source>
            <translation>Refinamento (ligado por padrão; desmarcado, os pontos-chave são escritos como detectados): correspondência
por mínimos quadrados (Gruen 1985, 6 parâmetros afins + 2 radiométricos) de cada medição de um rastro
contra um modelo de 21 x 21 px em torno de sua medição na primeira imagem do rastro (mantida
fixa), nas imagens em tons de cinza em resolução total (cada uma lida uma segunda vez, uma de cada vez),
partindo da afim local entre as duas imagens; uma correspondência que a correspondência por mínimos quadrados
leva a outro ponto (deslocada mais de 3 px, correlação abaixo de 0,7) é descartada, assim como uma
que ela recusa por outro motivo (saiu da sua janela, sem convergência); uma medição que ela não pode
tentar (modelo na borda da imagem, sem afim inicial) mantém o ponto-chave.</translation>
        </message>
        <message>
            <source>Output: the image-observation CSV (type tie, point ids tp000001 ..., target_id empty), read
directly by Bundle adjustment. sigma_px: the value given, or 0.5 px times the detection
reduction factor; refined measurements: the least-squares sigma (at least 0.02 px); the
track's first-image measurement: the median of its track's refined sigmas.</source>
            <translation>Saída: o CSV de observações de imagem (type tie, ids de pontos tp000001 ..., target_id vazio), lido
diretamente pelo Ajustamento por feixes de raios. sigma_px: o valor dado, ou 0,5 px vezes o fator de
redução da detecção; medidas refinadas: o sigma dos mínimos quadrados (no mínimo 0,02 px); a
medida da primeira imagem da trilha: a mediana dos sigmas refinados da sua trilha.</translation>
        </message>
        <message>
            <source>Images (files or folders)</source>
            <translation>Imagens (arquivos ou pastas)</translation>
        </message>
        <message>
            <source>image files, or folders whose images are all taken; the image id is the file name without extension</source>
            <translation>arquivos de imagem, ou pastas cujas imagens são todas tomadas; o id da imagem é o nome do arquivo sem extensão</translation>
        </message>
        <message>
            <source>Exterior orientation (CSV) for pair selection</source>
            <translation>Orientação exterior (CSV) para a seleção de pares</translation>
        </message>
        <message>
            <source>with CAMERA: pairs from ground footprints</source>
            <translation>com CAMERA: pares a partir das projeções no terreno</translation>
        </message>
        <message>
            <source>CSV files (*.csv *.txt)</source>
            <translation>Arquivos CSV (*.csv *.txt)</translation>
        </message>
        <message>
            <source>Camera (JSON)</source>
            <translation>Câmera (JSON)</translation>
        </message>
        <message>
            <source>perspective or fisheye; with EO: pairs from ground footprints; a fisheye camera is needed for fisheye images (their matches are verified on the camera's rays)</source>
            <translation>perspectiva ou olho de peixe; com EO: pares pelas projeções no terreno; uma câmera olho de peixe é necessária para imagens olho de peixe (as suas correspondências são verificadas sobre os raios da câmera)</translation>
        </message>
        <message>
            <source>JSON files (*.json)</source>
            <translation>Arquivos JSON (*.json)</translation>
        </message>
        <message>
            <source>Mapping CRS of the EO</source>
            <translation>SRC de mapeamento da OE</translation>
        </message>
        <message>
            <source>the EO is checked against its area of use</source>
            <translation>a OE é conferida com a área de uso do SRC</translation>
        </message>
        <message>
            <source>Mean terrain height</source>
            <translation>Altura média do terreno</translation>
        </message>
        <message>
            <source>the plane the footprints are computed on (EO heights)</source>
            <translation>o plano sobre o qual as projeções no terreno são calculadas (alturas da EO)</translation>
        </message>
        <message>
            <source>Detector</source>
            <translation>Detector</translation>
        </message>
        <message>
            <source>SIFT (Lowe 2004)</source>
            <translation>SIFT (Lowe 2004)</translation>
        </message>
        <message>
            <source>ORB (fast)</source>
            <translation>ORB (rápido)</translation>
        </message>
        <message>
            <source>Features per image</source>
            <translation>Feições por imagem</translation>
        </message>
        <message>
            <source>SIFT keypoints kept per image (Keypoints kept); 6 kite images, all pairs: 16,384 (default) 3,664 tracks seen in 3 images, COLMAP at its 8,192 3,662-3,730, for about half its CPU; 4,000: 1,190 (bench/matching.md)</source>
            <translation>pontos-chave SIFT mantidos por imagem (Pontos-chave mantidos); 6 imagens de pipa, todos os pares: 16.384 (padrão) 3.664 trilhas vistas em 3 imagens, o COLMAP com os seus 8.192 3.662-3.730, por cerca de metade da sua CPU; 4.000: 1.190 (bench/matching.md)</translation>
        </message>
        <message>
            <source>Keypoints kept (SIFT)</source>
            <translation>Pontos-chave mantidos (SIFT)</translation>
        </message>
        <message>
            <source>which Features per image SIFT keeps when it finds more: the largest scales (COLMAP's rule) or the strongest response (OpenCV's). Two kite images, 8,192 features: 3,313 verified matches against 2,436 (+36 %); simulated block, 1,500 features: 3-6 % fewer matches, keypoints 0.15 against 0.12 px from the truth before the refinement, the same 0.021 px after it: with REFINE off, the strongest response is the precise choice (bench/matching.md)</source>
            <translation>quais Feições por imagem o SIFT mantém quando encontra mais: as das maiores escalas (a regra do COLMAP) ou as de resposta mais forte (a do OpenCV). Duas imagens de pipa, 8.192 feições: 3.313 correspondências verificadas contra 2.436 (+36 %); bloco simulado, 1.500 feições: 3-6 % menos correspondências, pontos-chave a 0,15 contra 0,12 px da verdade antes do refinamento, os mesmos 0,021 px depois dele: com REFINE desligado, a resposta mais forte é a escolha precisa (bench/matching.md)</translation>
        </message>
        <message>
            <source>largest scales (COLMAP's rule)</source>
            <translation>maiores escalas (a regra do COLMAP)</translation>
        </message>
        <message>
            <source>strongest response (OpenCV's)</source>
            <translation>resposta mais forte (a do OpenCV)</translation>
        </message>
        <message>
            <source>SIFT contrast threshold</source>
            <translation>Limiar de contraste do SIFT</translation>
        </message>
        <message>
            <source>OpenCV's contrastThreshold (grey levels / 255 over 3 layers per octave): lower finds weaker extrema, so that low-contrast images fill Features per image; 6 kite images at 8,192 features (strongest kept): OpenCV's 0.04 finds 5,116 per image, 0.02 fills the budget, verified matches 5,954 -&gt; 9,874; 0.01 (default) gives the same within 0.4 % and fills it at half the detection size</source>
            <translation>o contrastThreshold do OpenCV (níveis de cinza / 255 em 3 camadas por oitava): um valor menor encontra extremos mais fracos, para que imagens de baixo contraste preencham as Feições por imagem; 6 imagens de pipa com 8.192 feições (as mais fortes mantidas): o 0,04 do OpenCV encontra 5.116 por imagem, 0,02 preenche o orçamento, correspondências verificadas 5.954 -&gt; 9.874; 0,01 (padrão) dá o mesmo a 0,4 % e o preenche na metade do tamanho de detecção</translation>
        </message>
        <message>
            <source>RootSIFT descriptors (Arandjelovic &amp; Zisserman 2012)</source>
            <translation>Descritores RootSIFT (Arandjelovic &amp; Zisserman 2012)</translation>
        </message>
        <message>
            <source>SIFT descriptors L1-normalised and square-rooted before matching (the Hellinger kernel; on by default, as in COLMAP); 6 kite images at 8,192 features: 5,954 -&gt; 6,118 verified matches (+3 %) for +7 % CPU</source>
            <translation>descritores SIFT normalizados em L1 e com raiz quadrada antes da correspondência (o núcleo de Hellinger; ativo por padrão, como no COLMAP); 6 imagens de pipa com 8.192 feições: 5.954 -&gt; 6.118 correspondências verificadas (+3 %) por +7 % de CPU</translation>
        </message>
        <message>
            <source>Guided matching along the epipolar lines</source>
            <translation>Correspondência guiada ao longo das linhas epipolares</translation>
        </message>
        <message>
            <source>after the fundamental matrix, every keypoint is matched again among its 8 nearest descriptors within the RANSAC threshold of its epipolar line (on by default); 6 kite images, 16,384 features: 27,075 -&gt; 28,427 verified matches (+5 %), 3-image tracks 3,582 -&gt; 3,876 (+8 %), CPU +6 %; simulated block: +1.7 % matches, refined 0.0212 -&gt; 0.0213 px median, the same 2 wrong tracks of 4,400</source>
            <translation>depois da matriz fundamental, cada ponto-chave é associado de novo entre os seus 8 descritores mais próximos dentro do limiar do RANSAC da sua linha epipolar (ativo por padrão); 6 imagens de pipa, 16.384 feições: 27.075 -&gt; 28.427 correspondências verificadas (+5 %), trilhas de 3 imagens 3.582 -&gt; 3.876 (+8 %), CPU +6 %; bloco simulado: +1,7 % de correspondências, refinado 0,0212 -&gt; 0,0213 px de mediana, as mesmas 2 trilhas erradas em 4.400</translation>
        </message>
        <message>
            <source>Detection size (longer side, 0 = full resolution)</source>
            <translation>Tamanho de detecção (lado maior, 0 = resolução completa)</translation>
        </message>
        <message>
            <source>the image is reduced by the smallest integer factor that brings its longer side to at most this (2,000 by default: images of 2,001-4,000 px at half size); 6 kite images (2,136 px), 16,384 features: half size 3,980 tracks seen in 3 images against 3,917 at full size, for 5.0 s of detection instead of 13.3 s</source>
            <translation>a imagem é reduzida pelo menor fator inteiro que leva o seu lado maior a no máximo este valor (2.000 por padrão: imagens de 2.001-4.000 px na metade do tamanho); 6 imagens de pipa (2.136 px), 16.384 feições: na metade do tamanho 3.980 trilhas vistas em 3 imagens contra 3.917 em tamanho pleno, por 5,0 s de detecção em vez de 13,3 s</translation>
        </message>
        <message>
            <source>Ratio test (best / second best)</source>
            <translation>Teste de razão (melhor / segundo melhor)</translation>
        </message>
        <message>
            <source>RANSAC threshold (epipolar distance)</source>
            <translation>Limiar do RANSAC (distância epipolar)</translation>
        </message>
        <message>
            <source>RANSAC method</source>
            <translation>Método RANSAC</translation>
        </message>
        <message>
            <source>MAGSAC++</source>
            <translation>MAGSAC++</translation>
        </message>
        <message>
            <source>RANSAC</source>
            <translation>RANSAC</translation>
        </message>
        <message>
            <source>Minimum inliers per pair</source>
            <translation>Mínimo de inliers por par</translation>
        </message>
        <message>
            <source>Minimum track length</source>
            <translation>Comprimento mínimo da trilha</translation>
        </message>
        <message>
            <source>Pairs</source>
            <translation>Pares</translation>
        </message>
        <message>
            <source>footprints with EO, else sequential</source>
            <translation>projeções no terreno com EO, senão sequencial</translation>
        </message>
        <message>
            <source>footprints (EO + camera)</source>
            <translation>projeções no terreno (EO + câmera)</translation>
        </message>
        <message>
            <source>all pairs</source>
            <translation>todos os pares</translation>
        </message>
        <message>
            <source>sequential window</source>
            <translation>janela sequencial</translation>
        </message>
        <message>
            <source>Sequential window</source>
            <translation>Janela sequencial</translation>
        </message>
        <message>
            <source>Minimum footprint overlap</source>
            <translation>Sobreposição mínima das projeções no terreno</translation>
        </message>
        <message>
            <source>share of the smaller footprint</source>
            <translation>fração da menor projeção no terreno</translation>
        </message>
        <message>
            <source>Least-squares refinement (Gruen 1985)</source>
            <translation>Refinamento por mínimos quadrados (Gruen 1985)</translation>
        </message>
        <message>
            <source>on (default): every measurement is moved to its least-squares match with the track's first image; off: the keypoints as detected. Median error against the truth, on / off: simulated block 0.021 / 0.075 px (95th percentile 0.06 / 0.36 px); graffiti wall, a change of viewpoint, 0.34 / 0.75 px; boat (zoom, rotation) 0.27 / 0.38 px. On costs a second full-resolution read of every image and +25 to +40 % CPU time (see bench/matching.md)</source>
            <translation>ligado (padrão): cada medição é movida para a sua correspondência por mínimos quadrados com a primeira imagem do rastro; desligado: os pontos-chave como detectados. Erro mediano em relação à verdade, ligado / desligado: bloco simulado 0,021 / 0,075 px (percentil 95 0,06 / 0,36 px); muro graffiti, uma mudança de ponto de vista, 0,34 / 0,75 px; boat (zoom, rotação) 0,27 / 0,38 px. Ligado custa uma segunda leitura em resolução total de cada imagem e +25 a +40 % de tempo de CPU (ver bench/matching.md)</translation>
        </message>
        <message>
            <source>sigma_px written (0 = 0.5 px x reduction)</source>
            <translation>sigma_px gravado (0 = 0,5 px x redução)</translation>
        </message>
        <message>
            <source>Tie points (observation CSV)</source>
            <translation>Pontos de enlace (CSV de observações)</translation>
        </message>
        <message>
            <source>CSV files (*.csv)</source>
            <translation>Arquivos CSV (*.csv)</translation>
        </message>
        <message>
            <source>Pair table (CSV)</source>
            <translation>Tabela de pares (CSV)</translation>
        </message>
        <message>
            <source>Tie points (tracks)</source>
            <translation>Pontos de enlace (trilhas)</translation>
        </message>
        <message>
            <source>Image measurements</source>
            <translation>Medições nas imagens</translation>
        </message>
        <message>
            <source>Image pairs tried</source>
            <translation>Pares de imagens tentados</translation>
        </message>
        <message>
            <source>Image pairs kept</source>
            <translation>Pares de imagens mantidos</translation>
        </message>
        <message>
            <source>Pairs: with an exterior orientation and a camera, the pairs whose ground footprints (image
corners met with the plane at Mean terrain height) overlap by at least Minimum overlap of the
smaller footprint; without them, each image with the next Window images in file-name order
(sequential), or all pairs. An image the EO table lacks is paired with every image.</source>
            <translation type="vanished">Pares: com uma orientação exterior e uma câmera, os pares cujas projeções no terreno (cantos da imagem
intersectados com o plano na Altura média do terreno) se sobrepõem em pelo menos Sobreposição mínima da
menor projeção; sem elas, cada imagem com as próximas Janela imagens na ordem dos nomes de arquivo
(sequencial), ou todos os pares. Uma imagem ausente da tabela de EO é pareada com todas as imagens.</translation>
        </message>
        <message>
            <source>Finds tie points in a block of images without an operator. Features: SIFT (Lowe 2004) or
ORB (Rublee et al. 2011, faster, less precise), detected once per image, on the image reduced
by the smallest integer factor that brings its longer side to at most Detection size (0: full
resolution; reductions by 2, 4 and 8 are made while decoding JPEGs); the keypoints are
scaled back to full-resolution pixels.</source>
            <translation type="vanished">Encontra pontos de enlace em um bloco de imagens sem operador. Feições: SIFT (Lowe 2004) ou
ORB (Rublee et al. 2011, mais rápido, menos preciso), detectadas uma vez por imagem, na imagem reduzida
pelo menor fator inteiro que leva o seu lado maior a no máximo Tamanho de detecção (0: resolução
completa; reduções por 2, 4 e 8 são feitas durante a decodificação de JPEGs); os pontos-chave são
reescalados para pixels da resolução completa.</translation>
        </message>
        <message>
            <source>Matching: nearest neighbours in descriptor space (FLANN k-d trees for SIFT, Muja &amp; Lowe 2009;
brute force for ORB), Lowe's ratio test, a mutual check, then RANSAC on the fundamental
matrix (Fischler &amp; Bolles 1981; MAGSAC++ by default) with a threshold on the distance to the
epipolar line in full-resolution pixels. Pairs with fewer than Minimum inliers are dropped
(the pair table gives the reason). Tracks: the matches of all pairs are merged (connected
components); a track holding two different points of one image is dropped, as are tracks
seen in fewer than Minimum track length images.</source>
            <translation type="vanished">Correspondência: vizinhos mais próximos no espaço dos descritores (árvores k-d do FLANN para SIFT, Muja &amp; Lowe 2009;
força bruta para ORB), teste de razão de Lowe, uma verificação mútua, e então RANSAC sobre a matriz
fundamental (Fischler &amp; Bolles 1981; MAGSAC++ por padrão) com um limiar sobre a distância à
linha epipolar em pixels da resolução completa. Pares com menos que Mínimo de inliers são descartados
(a tabela de pares dá o motivo). Trilhas: as correspondências de todos os pares são unidas (componentes
conexas); uma trilha que contém dois pontos diferentes de uma mesma imagem é descartada, assim como as trilhas
vistas em menos imagens que Comprimento mínimo da trilha.</translation>
        </message>
        <message>
            <source>Refinement (optional): least-squares matching (Gruen 1985, 6 affine + 2 radiometric
parameters) of every measurement of a track against a 21 x 21 px template around its
measurement in the track's first image (kept fixed), in the full-resolution grey images
(each read a second time, one at a time), starting from the local affine between the two
images; a match the least-squares matching calls another point (moved more than 3 px,
correlation below 0.7) is dropped, any other failure keeps the keypoint.</source>
            <translation type="vanished">Refinamento (opcional): correspondência por mínimos quadrados (Gruen 1985, 6 parâmetros
afins + 2 radiométricos) de cada medida de uma trilha contra um modelo de 21 x 21 px em torno da
sua medida na primeira imagem da trilha (mantida fixa), nas imagens em tons de cinza em resolução
plena (cada uma lida uma segunda vez, uma de cada vez), partindo da afinidade local entre as duas
imagens; uma correspondência que a correspondência por mínimos quadrados atribui a outro ponto
(deslocada mais de 3 px, correlação abaixo de 0,7) é descartada, qualquer outra falha mantém o ponto-chave.</translation>
        </message>
        <message>
            <source>moves every measurement to its least-squares match with the track's first image; costs a second full-resolution read of every image and about 0.3 ms of CPU per measurement (measured: 18 images of 12 Mpx, +35 % CPU time; median error 0.11 -&gt; 0.05 px, see bench/matching.md)</source>
            <translation type="vanished">move cada medida para a sua correspondência por mínimos quadrados com a primeira imagem da trilha; custa uma segunda leitura em resolução plena de cada imagem e cerca de 0,3 ms de CPU por medida (medido: 18 imagens de 12 Mpx, +35 % de tempo de CPU; erro mediano 0,11 -&gt; 0,05 px, ver bench/matching.md)</translation>
        </message>
        <message>
            <source>Orientation</source>
            <translation type="vanished">Orientação</translation>
        </message>
        <message>
            <source>Output: the image-observation CSV (type tie, point ids tp000001 ..., target_id empty), read
directly by Bundle adjustment. sigma_px: the value given, or 0.5 px times the detection
reduction factor. No least-squares refinement of the points yet.</source>
            <translation type="vanished">Saída: o CSV de observações de imagem (type tie, ids de pontos tp000001 ..., target_id vazio), lido
diretamente pelo Ajustamento por feixes de raios. sigma_px: o valor dado, ou 0,5 px vezes o fator de
redução da detecção. Ainda sem refinamento dos pontos por mínimos quadrados.</translation>
        </message>
    </context>
    <context>
        <name>lidarphoto:tlscalibration</name>
        <message>
            <source>TLS registration and self-calibration</source>
            <translation>Registro e autocalibração TLS</translation>
        </message>
        <message>
            <source>Laser scanning</source>
            <translation>Varredura a laser</translation>
        </message>
        <message>
            <source>register laser scanner stations on targets and estimate the scanner's systematic errors</source>
            <translation>registrar estações de laser scanner sobre alvos e estimar os erros sistemáticos do escâner</translation>
        </message>
        <message>
            <source>One least-squares adjustment of all stations and targets (Carvalho, Correa &amp; dos Santos,
Eq. 1): each station's position and omega, phi, kappa, the targets' coordinates and the
scanner's additional parameters (APs) in polar form (Eqs. 2-5): the paper's set a0 (range
offset), b1 sec(alpha) (collimation), b2 tan(alpha) (trunnion axis), c0 (vertical index), or
Lichti's (2007) extended set (range scale and cyclic terms, circle eccentricities, encoder
errors). AP set none: registration only.</source>
            <translation>Um único ajustamento por mínimos quadrados de todas as estações e alvos (Carvalho, Correa &amp; dos
Santos, Eq. 1): a posição e omega, phi, kappa de cada estação, as coordenadas dos alvos e os
parâmetros adicionais (PAs) do escâner na forma polar (Eqs. 2-5): o conjunto do artigo a0
(deslocamento da distância), b1 sec(alfa) (colimação), b2 tan(alfa) (eixo secundário), c0
(índice vertical), ou o conjunto estendido de Lichti (2007) (escala da distância e termos
cíclicos, excentricidades dos círculos, erros dos codificadores). Conjunto de PAs none: apenas
o registro.</translation>
        </message>
        <message>
            <source>Observations (CSV): station_id,target_id,range,hz_deg,vt_deg[,s_range,s_hz,s_vt] (metres,
degrees, elevation angle; a vertical angle beyond +-90 deg is a face-II reading; sigmas in m
and arc-seconds), or hz_gon/vt_gon, or hz/vt in ANGLE UNIT; or scanner-frame target centres
station_id,target_id,x,y,z[,s_x,s_y,s_z]. Rows without sigmas take DEFAULT SIGMAS.</source>
            <translation>Observações (CSV): station_id,target_id,range,hz_deg,vt_deg[,s_range,s_hz,s_vt] (metros, graus,
ângulo de elevação; um ângulo vertical além de +-90 graus é uma leitura na posição II;
desvios-padrão em m e em segundos de arco), ou hz_gon/vt_gon, ou hz/vt na UNIDADE ANGULAR; ou
centros de alvos no referencial do escâner station_id,target_id,x,y,z[,s_x,s_y,s_z]. Linhas sem
desvios-padrão recebem os DESVIOS-PADRÃO PADRÃO.</translation>
        </message>
        <message>
            <source>Control (optional): target_id,X,Y,Z[,s_X,s_Y,s_Z] (sigma 0 or none: fixed); it defines the
datum. Without control the datum is inner constraints on the targets (free network) or the
reference station. Stations (optional): station_id, approximate X,Y,Z and omega_deg,
phi_deg,kappa_deg, levelled (1/0). A levelled station's omega and phi are compensator
observations with TILT SIGMA; others are free.</source>
            <translation>Controle (opcional): target_id,X,Y,Z[,s_X,s_Y,s_Z] (sigma 0 ou nenhum: fixo); ele define o
referencial (datum). Sem controle, o referencial são injunções internas sobre os alvos (rede
livre) ou a estação de referência. Estações (opcional): station_id, X,Y,Z aproximados e
omega_deg,phi_deg,kappa_deg, nivelada (1/0). O omega e o phi de uma estação nivelada são
observações do compensador com o SIGMA DE INCLINAÇÃO; os das outras são livres.</translation>
        </message>
        <message>
            <source>The report gives sigma0 and the global test, Baarda's data snooping, each AP's t-test, the
correlation matrix of APs and station parameters with the strongly correlated pairs named and
the network design that separates them (Lichti 2010: targets over the full vertical range,
two faces, stations tilted by 90 degrees). SELECT APS removes correlated and insignificant
terms one by one. A parameter the network cannot determine is an error that says why.</source>
            <translation>O relatório dá sigma0 e o teste global, o data snooping de Baarda, o teste t de cada PA, a
matriz de correlação dos PAs e dos parâmetros das estações, com os pares fortemente
correlacionados nomeados e a geometria de rede que os separa (Lichti 2010: alvos em toda a
faixa vertical, duas posições da luneta, estações inclinadas de 90 graus). SELECT APS remove,
um a um, os termos correlacionados e não significativos. Um parâmetro que a rede não consegue
determinar é um erro que diz o porquê.</translation>
        </message>
        <message>
            <source>Registered clouds (optional): SCANS are the stations' scans (LAS/LAZ, PLY, E57; points in
the scanner frame; the station id is the file name without its suffix, as in Extract TLS
targets). Each is written to OUTPUT_FOLDER as &lt;station_id&gt;_registered.laz (LAZ scans) or
.las (the others) with its points in the common frame, X = M' d + X0 with the adjusted
pose: the control's frame; without control the reference station's (its pose in the stations
table, else the origin unrotated), held exactly (DATUM reference) or on average over the
targets (inner constraints). With APs estimated and APPLY APS on,
each point's recorded polar coordinates are corrected by the estimated APs before the
pose is applied, taken as face-I readings (elevation within +-90 deg): turn it off for
scans that mix both faces (a panoramic scanner's second half-turn), which then get the
rigid pose only. LAS/LAZ scans are streamed in chunks (every dimension and VLR kept);
PLY/E57 scans are read whole. All files appear together or none (a bad scan: none).</source>
            <translation>Nuvens registradas (opcional): SCANS são as varreduras das estações (LAS/LAZ, PLY, E57; pontos
no referencial do escâner; o identificador da estação é o nome do arquivo sem a extensão, como
em Extrair alvos TLS). Cada uma é gravada em OUTPUT_FOLDER como &lt;station_id&gt;_registered.laz
(varreduras LAZ) ou .las (as outras), com os seus pontos no referencial comum, X = M' d + X0
com a pose ajustada: o referencial do controle; sem controle, o da estação de referência (a sua
pose na tabela de estações, senão a origem sem rotação), mantido exatamente (DATUM reference)
ou em média sobre os alvos (injunções internas). Com PAs estimados e APPLY APS ligado, as
coordenadas polares registradas de cada ponto são corrigidas pelos PAs estimados antes de
aplicar a pose, tomadas como leituras na posição I (elevação dentro de +-90 graus): desligue-o
para varreduras que misturam as duas posições (a segunda meia-volta de um escâner panorâmico),
que então recebem apenas a pose rígida. As varreduras LAS/LAZ são lidas em blocos (todas as
dimensões e VLRs mantidas); as varreduras PLY/E57 são lidas inteiras. Todos os arquivos
aparecem juntos ou nenhum (uma varredura ruim: nenhum).</translation>
        </message>
        <message>
            <source>## Checks of the result
The run fails (nothing is written but the HTML report, which says why) when the adjustment
did not converge, when its global test fails with sigma0 above MAX SIGMA0, or when data
snooping rejected more observations than its false alarms explain (the upper tail of their
binomial count below 0.001: a model that does not fit the data, e.g. APs missing, or many
blunders; the global test of the observations left then proves nothing). With ACCEPT
DOUBTFUL the outputs are written and each table starts with a warning (comment lines
beginning with #).</source>
            <translation>## Verificações do resultado
A execução falha (nada é gravado além do relatório HTML, que diz o motivo) quando o ajustamento
não convergiu, quando o seu teste global falha com sigma0 acima de MAX SIGMA0, ou quando o
data snooping rejeitou mais observações do que os seus falsos alarmes explicam (a cauda
superior da sua contagem binomial abaixo de 0,001: um modelo que não se ajusta aos dados, por
exemplo APs em falta, ou muitos erros grosseiros; o teste global das observações restantes
então nada prova). Com ACCEPT DOUBTFUL as saídas são gravadas e cada tabela começa com um aviso
(linhas de comentário iniciadas por #).</translation>
        </message>
        <message>
            <source>Observations (CSV)</source>
            <translation>Observações (CSV)</translation>
        </message>
        <message>
            <source>CSV files (*.csv *.txt)</source>
            <translation>Arquivos CSV (*.csv *.txt)</translation>
        </message>
        <message>
            <source>Control targets (CSV)</source>
            <translation>Alvos de controle (CSV)</translation>
        </message>
        <message>
            <source>Stations (CSV)</source>
            <translation>Estações (CSV)</translation>
        </message>
        <message>
            <source>approximate poses, compensator tilts, levelled flags; when given, every observed station must be in it</source>
            <translation>poses aproximadas, inclinações do compensador, indicadores de nivelamento; quando informada, toda estação observada deve estar nela</translation>
        </message>
        <message>
            <source>Angle unit of hz/vt columns</source>
            <translation>Unidade angular das colunas hz/vt</translation>
        </message>
        <message>
            <source>only for columns named hz and vt; hz_deg/hz_gon say their own unit</source>
            <translation>apenas para as colunas chamadas hz e vt; hz_deg/hz_gon dizem a sua própria unidade</translation>
        </message>
        <message>
            <source>Default sigmas: range, horizontal, vertical</source>
            <translation>Desvios-padrão padrão: distância, horizontal, vertical</translation>
        </message>
        <message>
            <source>for rows without s_range, s_hz, s_vt (or s_x, s_y, s_z: the range sigma)</source>
            <translation>para linhas sem s_range, s_hz, s_vt (ou s_x, s_y, s_z: o desvio-padrão da distância)</translation>
        </message>
        <message>
            <source>Additional parameters</source>
            <translation>Parâmetros adicionais</translation>
        </message>
        <message>
            <source>none (registration only)</source>
            <translation>nenhum (apenas o registro)</translation>
        </message>
        <message>
            <source>paper: a0, b1, b2, c0</source>
            <translation>artigo: a0, b1, b2, c0</translation>
        </message>
        <message>
            <source>extended (Lichti 2007): a0-a3, b1-b6, c0-c3</source>
            <translation>estendido (Lichti 2007): a0-a3, b1-b6, c0-c3</translation>
        </message>
        <message>
            <source>AP terms (overrides the set)</source>
            <translation>Termos de PA (substituem o conjunto)</translation>
        </message>
        <message>
            <source>comma-separated, e.g. a0,b1,b2,c0,a1</source>
            <translation>separados por vírgulas, por exemplo, a0,b1,b2,c0,a1</translation>
        </message>
        <message>
            <source>Select the APs by significance and correlation</source>
            <translation>Selecionar os PAs por significância e correlação</translation>
        </message>
        <message>
            <source>Stations levelled by the compensator</source>
            <translation>Estações niveladas pelo compensador</translation>
        </message>
        <message>
            <source>default for stations whose table does not say</source>
            <translation>padrão para as estações cuja tabela não o diz</translation>
        </message>
        <message>
            <source>Compensator sigma</source>
            <translation>Desvio-padrão do compensador</translation>
        </message>
        <message>
            <source>Datum without control</source>
            <translation>Referencial (datum) sem controle</translation>
        </message>
        <message>
            <source>inner constraints on the targets (free network)</source>
            <translation>injunções internas sobre os alvos (rede livre)</translation>
        </message>
        <message>
            <source>reference station held at its pose</source>
            <translation>estação de referência mantida na sua pose</translation>
        </message>
        <message>
            <source>Reference station</source>
            <translation>Estação de referência</translation>
        </message>
        <message>
            <source>default: the first station of the stations table with a position, else the first observed</source>
            <translation>padrão: a primeira estação da tabela de estações com posição, senão a primeira observada</translation>
        </message>
        <message>
            <source>Wavelength of the cyclic range terms</source>
            <translation>Comprimento de onda dos termos cíclicos da distância</translation>
        </message>
        <message>
            <source>Data snooping (Baarda)</source>
            <translation>Detecção de erros grosseiros (data snooping de Baarda)</translation>
        </message>
        <message>
            <source>Strong correlation at |r| &gt;=</source>
            <translation>Correlação forte para |r| &gt;=</translation>
        </message>
        <message>
            <source>Largest sigma0 when the global test fails</source>
            <translation>Maior sigma0 quando o teste global falha</translation>
        </message>
        <message>
            <source>a failed global test with sigma0 above this fails the run (wrong sigmas, a model that does not fit, or blunders data snooping did not catch)</source>
            <translation>um teste global que falha com sigma0 acima deste valor faz a execução falhar (desvios-padrão errados, um modelo que não se ajusta, ou erros grosseiros que o data snooping não detectou)</translation>
        </message>
        <message>
            <source>Write the results even when the checks fail</source>
            <translation>Gravar os resultados mesmo quando as verificações falham</translation>
        </message>
        <message>
            <source>no convergence, global test beyond MAX_SIGMA0 or more rejections than data snooping's false alarms explain: write the outputs anyway, each table with a warning at its top</source>
            <translation>sem convergência, teste global além de MAX_SIGMA0 ou mais rejeições do que os falsos alarmes do data snooping explicam: grava as saídas mesmo assim, cada tabela com um aviso no início</translation>
        </message>
        <message>
            <source>Scans to register (LAS/LAZ, PLY, E57; one station per file)</source>
            <translation>Varreduras a registrar (LAS/LAZ, PLY, E57; uma estação por arquivo)</translation>
        </message>
        <message>
            <source>the file name without its suffix is the station id</source>
            <translation>o nome do arquivo sem a extensão é o identificador da estação</translation>
        </message>
        <message>
            <source>Correct the scan points by the estimated APs</source>
            <translation>Corrigir os pontos da varredura pelos PAs estimados</translation>
        </message>
        <message>
            <source>face-I readings; off: the rigid pose only</source>
            <translation>leituras na posição I; desligado: apenas a pose rígida</translation>
        </message>
        <message>
            <source>Station poses (CSV)</source>
            <translation>Poses das estações (CSV)</translation>
        </message>
        <message>
            <source>CSV files (*.csv)</source>
            <translation>Arquivos CSV (*.csv)</translation>
        </message>
        <message>
            <source>Additional parameters (CSV)</source>
            <translation>Parâmetros adicionais (CSV)</translation>
        </message>
        <message>
            <source>Target coordinates (CSV)</source>
            <translation>Coordenadas dos alvos (CSV)</translation>
        </message>
        <message>
            <source>Residuals (CSV)</source>
            <translation>Resíduos (CSV)</translation>
        </message>
        <message>
            <source>Report (HTML)</source>
            <translation>Relatório (HTML)</translation>
        </message>
        <message>
            <source>HTML files (*.html)</source>
            <translation>Arquivos HTML (*.html)</translation>
        </message>
        <message>
            <source>Registered scans (folder)</source>
            <translation>Varreduras registradas (pasta)</translation>
        </message>
        <message>
            <source>needs SCANS</source>
            <translation>requer SCANS</translation>
        </message>
        <message>
            <source>Sigma0 a-posteriori</source>
            <translation>Sigma0 a posteriori</translation>
        </message>
        <message>
            <source>Registered scans written</source>
            <translation>Varreduras registradas gravadas</translation>
        </message>
        <message>
            <source>Observations rejected</source>
            <translation>Observações rejeitadas</translation>
        </message>
        <message>
            <source>Additional parameters estimated</source>
            <translation>Parâmetros adicionais estimados</translation>
        </message>
        <message>
            <source>Calibration</source>
            <translation type="vanished">Calibração</translation>
        </message>
    </context>
    <context>
        <name>lidarphoto:trajectorytoeo</name>
        <message>
            <source>Trajectory to exterior orientation</source>
            <translation>Trajetória para orientação exterior</translation>
        </message>
        <message>
            <source>Aerotriangulation</source>
            <translation>Aerotriangulação</translation>
        </message>
        <message>
            <source>INS/GNSS trajectory + camera mount -&gt; exterior orientation per image</source>
            <translation>trajetória INS/GNSS + montagem da câmera -&gt; orientação exterior por imagem</translation>
        </message>
        <message>
            <source>Computes the exterior orientation (perspective centre and omega, phi, kappa) of every image
from the INS/GNSS solution at its exposure time (direct georeferencing: X_pc = X_ins +
R_b^m a_b, R_c^m = R_b^m R_c^b, composed rigorously through the Earth-centred frame, so grid
convergence and Earth curvature are accounted for).</source>
            <translation>Calcula a orientação exterior (centro perspectivo e omega, phi, kappa) de cada imagem a partir
da solução INS/GNSS no seu instante de exposição (georreferenciamento direto: X_pc = X_ins +
R_b^m a_b, R_c^m = R_b^m R_c^b, composta rigorosamente através do referencial geocêntrico, de
modo que a convergência meridiana e a curvatura da Terra são levadas em conta).</translation>
        </message>
        <message>
            <source>## Trajectory table (INPUT)
CSV with a header row (column names are case-insensitive) and one row per image:
- image_id (unique) and time (seconds);
- either easting, northing, height in the mapping CRS, or latitude, longitude, height
  (degrees, on the geodetic datum of the CRS); heights in metres;
- roll, pitch, heading in degrees; body frame x forward, y right, z down; heading clockwise
  from true north;
- optional group (flight line, camera, ...).</source>
            <translation>## Tabela da trajetória (INPUT)
CSV com uma linha de cabeçalho (os nomes das colunas não diferenciam maiúsculas de minúsculas)
e uma linha por imagem:
- image_id (único) e time (segundos);
- ou easting, northing, height no SRC de mapeamento, ou latitude, longitude, height (graus, no
  datum geodésico do SRC); alturas em metros;
- roll, pitch, heading em graus; referencial do corpo x para a frente, y para a direita, z para
  baixo; heading no sentido horário a partir do norte verdadeiro;
- group opcional (faixa de voo, câmera, ...).</translation>
        </message>
        <message>
            <source>## Mounting
Lever arm: the camera perspective centre in the body frame, metres. Camera mount: the
nominal camera-to-body rotation; custom uses the mount matrix (9 numbers, row-major R_c^b).
Boresight: the small misalignment in degrees about the camera axes x, y, z.</source>
            <translation>## Montagem
Braço de alavanca: o centro perspectivo da câmera no referencial do corpo, em metros. Montagem
da câmera: a rotação nominal da câmera para o corpo; custom usa a matriz de montagem (9
números, R_c^b por linhas). Boresight: o pequeno desalinhamento em graus em torno dos eixos x,
y, z da câmera.</translation>
        </message>
        <message>
            <source>## Outputs
A PointZ layer in the mapping CRS with image_id, time, group, X, Y, Z, omega_deg, phi_deg,
kappa_deg (angles relative to the grid frame at each image), optionally the same table as
CSV (on the command line, printed when no file is given), and the number of images.</source>
            <translation>## Saídas
Uma camada PointZ no SRC de mapeamento com image_id, time, group, X, Y, Z, omega_deg, phi_deg,
kappa_deg (ângulos relativos ao referencial da quadrícula em cada imagem), opcionalmente a
mesma tabela em CSV (na linha de comando, impressa quando nenhum arquivo é informado) e o
número de imagens.</translation>
        </message>
        <message>
            <source>Trajectory table (CSV)</source>
            <translation>Tabela da trajetória (CSV)</translation>
        </message>
        <message>
            <source>CSV files (*.csv *.txt)</source>
            <translation>Arquivos CSV (*.csv *.txt)</translation>
        </message>
        <message>
            <source>Mapping CRS (projected)</source>
            <translation>SRC de mapeamento (projetado)</translation>
        </message>
        <message>
            <source>projected CRS of the trajectory's eastings/northings and of the output</source>
            <translation>SRC projetado dos eastings/northings da trajetória e da saída</translation>
        </message>
        <message>
            <source>Lever arm x,y,z</source>
            <translation>Braço de alavanca x,y,z</translation>
        </message>
        <message>
            <source>camera perspective centre in the INS body frame (x forward, y right, z down)</source>
            <translation>centro perspectivo da câmera no referencial do corpo do INS (x para a frente, y para a direita, z para baixo)</translation>
        </message>
        <message>
            <source>Camera mount</source>
            <translation>Montagem da câmera</translation>
        </message>
        <message>
            <source>nominal camera-to-body rotation; custom uses MOUNT_MATRIX</source>
            <translation>rotação nominal da câmera para o corpo; custom usa MOUNT_MATRIX</translation>
        </message>
        <message>
            <source>image_top_forward: image top towards the flight direction (nose)</source>
            <translation>image_top_forward: topo da imagem no sentido do voo (nariz)</translation>
        </message>
        <message>
            <source>image_right_forward: image right side towards the flight direction</source>
            <translation>image_right_forward: lado direito da imagem no sentido do voo</translation>
        </message>
        <message>
            <source>image_bottom_forward: image bottom towards the flight direction</source>
            <translation>image_bottom_forward: base da imagem no sentido do voo</translation>
        </message>
        <message>
            <source>image_left_forward: image left side towards the flight direction</source>
            <translation>image_left_forward: lado esquerdo da imagem no sentido do voo</translation>
        </message>
        <message>
            <source>custom: custom matrix (MOUNT_MATRIX)</source>
            <translation>custom: matriz definida pelo usuário (MOUNT_MATRIX)</translation>
        </message>
        <message>
            <source>Mount matrix R_c^b (9 numbers, row-major)</source>
            <translation>Matriz de montagem R_c^b (9 números, por linhas)</translation>
        </message>
        <message>
            <source>the nominal mount R_c^b when MOUNT is custom</source>
            <translation>a montagem nominal R_c^b quando MOUNT é custom</translation>
        </message>
        <message>
            <source>Boresight domega,dphi,dkappa</source>
            <translation>Boresight domega,dphi,dkappa</translation>
        </message>
        <message>
            <source>small misalignment about the camera axes x, y, z (a larger rotation belongs in MOUNT)</source>
            <translation>pequeno desalinhamento em torno dos eixos x, y, z da câmera (uma rotação maior pertence a MOUNT)</translation>
        </message>
        <message>
            <source>Exterior orientation</source>
            <translation>Orientação exterior</translation>
        </message>
        <message>
            <source>Exterior orientation table (CSV)</source>
            <translation>Tabela de orientação exterior (CSV)</translation>
        </message>
        <message>
            <source>CSV files (*.csv)</source>
            <translation>Arquivos CSV (*.csv)</translation>
        </message>
        <message>
            <source>Number of images</source>
            <translation>Número de imagens</translation>
        </message>
        <message>
            <source>Direct georeferencing</source>
            <translation type="vanished">Georreferenciamento direto</translation>
        </message>
    </context>
</TS>
