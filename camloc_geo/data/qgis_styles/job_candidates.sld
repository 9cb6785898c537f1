<?xml version="1.0" encoding="UTF-8"?>
<StyledLayerDescriptor xmlns="http://www.opengis.net/sld" xmlns:se="http://www.opengis.net/se" xsi:schemaLocation="http://www.opengis.net/sld http://schemas.opengis.net/sld/1.1.0/StyledLayerDescriptor.xsd" xmlns:ogc="http://www.opengis.net/ogc" xmlns:xsi="http://www.w3.org/2001/XMLSchema-instance" xmlns:xlink="http://www.w3.org/1999/xlink" version="1.1.0">
 <NamedLayer>
  <se:Name>job_candidates</se:Name>
  <UserStyle>
   <se:Name>job_candidates</se:Name>
   <se:FeatureTypeStyle>
    <se:Rule>
     <se:Name>★ tie: another candidate fits the evidence nearly as well (odds under 10 to 1) more than 10 m away; add a viewing direction or a landmark to decide</se:Name>
     <se:Description>
      <se:Title>★ tie: another candidate fits the evidence nearly as well (odds under 10 to 1) more than 10 m away; add a viewing direction or a landmark to decide</se:Title>
     </se:Description>
     <ogc:Filter xmlns:ogc="http://www.opengis.net/ogc">
      <ogc:Not>
       <ogc:Or>
        <ogc:PropertyIsEqualTo>
         <ogc:Function name="coalesce">
          <ogc:PropertyName>ambiguous_with</ogc:PropertyName>
          <ogc:Literal>[]</ogc:Literal>
         </ogc:Function>
         <ogc:Literal></ogc:Literal>
        </ogc:PropertyIsEqualTo>
        <ogc:PropertyIsEqualTo>
         <ogc:Function name="coalesce">
          <ogc:PropertyName>ambiguous_with</ogc:PropertyName>
          <ogc:Literal>[]</ogc:Literal>
         </ogc:Function>
         <ogc:Literal>[]</ogc:Literal>
        </ogc:PropertyIsEqualTo>
       </ogc:Or>
      </ogc:Not>
     </ogc:Filter>
     <se:PointSymbolizer>
      <se:Graphic>
       <se:Mark>
        <se:WellKnownName>star</se:WellKnownName>
        <se:Fill>
         <se:SvgParameter name="fill">#d7191c</se:SvgParameter>
        </se:Fill>
        <se:Stroke>
         <se:SvgParameter name="stroke">#000000</se:SvgParameter>
         <se:SvgParameter name="stroke-width">0.5</se:SvgParameter>
        </se:Stroke>
       </se:Mark>
       <se:Size>18</se:Size>
      </se:Graphic>
     </se:PointSymbolizer>
    </se:Rule>
    <se:Rule>
     <se:Name>a camera's best candidate</se:Name>
     <se:Description>
      <se:Title>a camera's best candidate</se:Title>
     </se:Description>
     <ogc:Filter xmlns:ogc="http://www.opengis.net/ogc">
      <ogc:And>
       <ogc:Not>
        <ogc:Not>
         <ogc:Or>
          <ogc:PropertyIsEqualTo>
           <ogc:Function name="coalesce">
            <ogc:PropertyName>ambiguous_with</ogc:PropertyName>
            <ogc:Literal>[]</ogc:Literal>
           </ogc:Function>
           <ogc:Literal></ogc:Literal>
          </ogc:PropertyIsEqualTo>
          <ogc:PropertyIsEqualTo>
           <ogc:Function name="coalesce">
            <ogc:PropertyName>ambiguous_with</ogc:PropertyName>
            <ogc:Literal>[]</ogc:Literal>
           </ogc:Function>
           <ogc:Literal>[]</ogc:Literal>
          </ogc:PropertyIsEqualTo>
         </ogc:Or>
        </ogc:Not>
       </ogc:Not>
       <ogc:PropertyIsEqualTo>
        <ogc:PropertyName>rank</ogc:PropertyName>
        <ogc:Literal>1</ogc:Literal>
       </ogc:PropertyIsEqualTo>
      </ogc:And>
     </ogc:Filter>
     <se:PointSymbolizer>
      <se:Graphic>
       <se:Mark>
        <se:WellKnownName>circle</se:WellKnownName>
        <se:Fill>
         <se:SvgParameter name="fill">#fdae61</se:SvgParameter>
        </se:Fill>
        <se:Stroke>
         <se:SvgParameter name="stroke">#000000</se:SvgParameter>
         <se:SvgParameter name="stroke-width">0.5</se:SvgParameter>
        </se:Stroke>
       </se:Mark>
       <se:Size>11</se:Size>
      </se:Graphic>
     </se:PointSymbolizer>
    </se:Rule>
    <se:Rule>
     <se:Name>other candidates</se:Name>
     <se:Description>
      <se:Title>other candidates</se:Title>
     </se:Description>
     <!--Parser Error: 
syntax error, unexpected ELSE - Expression was: ELSE-->
     <se:PointSymbolizer>
      <se:Graphic>
       <se:Mark>
        <se:WellKnownName>circle</se:WellKnownName>
        <se:Fill>
         <se:SvgParameter name="fill">#2c7bb6</se:SvgParameter>
        </se:Fill>
        <se:Stroke>
         <se:SvgParameter name="stroke">#000000</se:SvgParameter>
         <se:SvgParameter name="stroke-width">0.5</se:SvgParameter>
        </se:Stroke>
       </se:Mark>
       <se:Size>8</se:Size>
      </se:Graphic>
     </se:PointSymbolizer>
    </se:Rule>
    <se:Rule>
     <se:TextSymbolizer>
      <se:Label>
       <!--SE Export for CASE WHEN rank > 1 OR coalesce(ambiguous_with, '[]') NOT IN ('', '[]') THEN concat('#', rank) END not implemented yet-->Placeholder</se:Label>
      <se:Font>
       <se:SvgParameter name="font-family">DejaVu LGC Sans</se:SvgParameter>
       <se:SvgParameter name="font-size">11</se:SvgParameter>
      </se:Font>
      <se:LabelPlacement>
       <se:PointPlacement>
        <se:AnchorPoint>
         <se:AnchorPointX>0</se:AnchorPointX>
         <se:AnchorPointY>0.5</se:AnchorPointY>
        </se:AnchorPoint>
        <se:Displacement>
         <se:DisplacementX>2.12</se:DisplacementX>
         <se:DisplacementY>2.12</se:DisplacementY>
        </se:Displacement>
       </se:PointPlacement>
      </se:LabelPlacement>
      <se:Halo>
       <se:Radius>2</se:Radius>
       <se:Fill>
        <se:SvgParameter name="fill">#ffffff</se:SvgParameter>
       </se:Fill>
      </se:Halo>
      <se:Fill>
       <se:SvgParameter name="fill">#000000</se:SvgParameter>
      </se:Fill>
      <se:Priority>100</se:Priority>
      <se:VendorOption name="maxDisplacement">4</se:VendorOption>
     </se:TextSymbolizer>
    </se:Rule>
   </se:FeatureTypeStyle>
  </UserStyle>
 </NamedLayer>
</StyledLayerDescriptor>
